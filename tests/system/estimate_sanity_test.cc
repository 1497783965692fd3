#include "system/estimate_sanity.h"

#include <gtest/gtest.h>

#include <limits>

#include "core/errors.h"
#include "system/synthetic_scene.h"

namespace cslam {
namespace {

struct Scene {
  SyntheticSequence seq;
  MotionEstimate truth;  // ground-truth camera; static landmarks at their true positions
};

Scene MakeScene() {
  SyntheticOptions o;
  o.preset = "outdoor";
  o.seed = 2;
  o.frames = 30;
  Scene s{GenerateSynthetic(o), {}};
  MotionEstimate& e = s.truth;
  e.range = {0, s.seq.num_frames()};
  e.world_from_cam = s.seq.world_from_cam;
  const int n = s.seq.observations.num_landmarks();
  e.landmark_cluster.assign(n, -1);
  e.landmark_in_cluster.assign(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (int i = 0; i < n; ++i)
    if (s.seq.landmark_object[i] == 0) {
      e.landmark_cluster[i] = 0;
      e.landmark_in_cluster[i] = s.seq.LandmarkInWorld(i, 0);
    }
  return s;
}

EstimateSanity Judge(const Scene& s, const MotionEstimate& e) {
  return JudgeEstimate(e, s.seq.observations, s.seq.camera, EstimateSanityOptions{});
}

TEST(EstimateSanity, TheGroundTruthIsUsable) {
  const Scene s = MakeScene();
  const EstimateSanity v = Judge(s, s.truth);
  EXPECT_TRUE(v.usable) << v.reason;
  EXPECT_GT(v.max_depth_m, 10.0);
  EXPECT_GT(v.landmarks, 100);
  EXPECT_EQ(v.far_landmarks, 0);
}

TEST(EstimateSanity, ACameraJumpBeyondTheMeasuredDepthIsRefused) {
  const Scene s = MakeScene();
  MotionEstimate e = s.truth;
  const double depth = Judge(s, e).max_depth_m;
  // Finite, so the old "every pose is finite" check let it through.
  for (int f = 20; f < e.range.size(); ++f) e.world_from_cam[f].translation().x() += 2.0 * depth;
  const EstimateSanity v = Judge(s, e);
  EXPECT_FALSE(v.usable);
  EXPECT_NE(v.reason.find("camera step"), std::string::npos) << v.reason;
}

TEST(EstimateSanity, ManyLandmarksFarBeyondTheMeasuredDepthAreRefusedAFewAreNot) {
  const Scene s = MakeScene();
  const double depth = Judge(s, s.truth).max_depth_m;
  std::vector<int> statics;
  for (int i = 0; i < static_cast<int>(s.truth.landmark_cluster.size()); ++i)
    if (s.truth.landmark_cluster[i] == 0) statics.push_back(i);
  auto push_away = [&](double fraction) {
    MotionEstimate e = s.truth;
    const int count = static_cast<int>(fraction * statics.size());
    for (int k = 0; k < count; ++k) e.landmark_in_cluster[statics[k]] *= 1e3 * depth;
    return Judge(s, e);
  };
  const EstimateSanity few = push_away(0.01);
  EXPECT_TRUE(few.usable) << few.reason;
  EXPECT_GT(few.far_landmarks, 0);
  const EstimateSanity many = push_away(0.5);
  EXPECT_FALSE(many.usable);
  EXPECT_NE(many.reason.find("landmarks"), std::string::npos) << many.reason;
}

TEST(EstimateSanity, ANonFinitePoseIsRefused) {
  const Scene s = MakeScene();
  MotionEstimate e = s.truth;
  e.world_from_cam[3].translation().y() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(Judge(s, e).usable);
}

TEST(EstimateSanity, OptionsCheckNamesTheField) {
  EstimateSanityOptions o;
  o.far_landmark_depths = 0.5;
  try {
    o.Check();
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("far_landmark_depths"), std::string::npos);
  }
}

}  // namespace
}  // namespace cslam
