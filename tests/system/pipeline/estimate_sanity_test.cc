#include "system/pipeline/estimate_sanity.h"

#include <gtest/gtest.h>

#include <limits>

#include "core/errors.h"
#include "system/synthetic/synthetic_scene.h"

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

/// The scene's truth with its moving objects as clusters at their true poses.
MotionEstimate WithTrueClusters(const Scene& s) {
  MotionEstimate e = s.truth;
  const TrackletTable& t = s.seq.observations;
  for (int object = 1; object < s.seq.num_objects(); ++object) {
    ClusterMotion m;
    m.cluster = object;
    for (int f = e.range.begin; f < e.range.end; ++f) {
      bool seen = false;
      for (const ObservationRef& ref : t.ObservationsAt(f)) seen |= s.seq.landmark_object[ref.landmark] == object;
      if (!seen) continue;
      m.frames.push_back(f);
      m.world_from_cluster.push_back(s.seq.world_from_object[object][f]);
      m.cam_from_cluster.push_back(s.seq.world_from_cam[f].inverse() * s.seq.world_from_object[object][f]);
    }
    if (m.frames.empty()) continue;
    e.clusters.push_back(m);
  }
  for (int i = 0; i < t.num_landmarks(); ++i)
    if (s.seq.landmark_object[i] > 0) {
      e.landmark_cluster[i] = s.seq.landmark_object[i];
      e.landmark_in_cluster[i] = s.seq.landmark_in_object[i];
    }
  return e;
}

/// Moves the cluster's pose at index k `metres` farther along the camera's optical axis.
void PushAway(MotionEstimate* e, size_t cluster, size_t k, double metres) {
  ClusterMotion& m = e->clusters[cluster];
  Pose shift = Pose::Identity();
  shift.translation() = Eigen::Vector3d(0, 0, metres);
  const Pose world_from_cam = m.world_from_cluster[k] * m.cam_from_cluster[k].inverse();
  m.cam_from_cluster[k] = shift * m.cam_from_cluster[k];
  m.world_from_cluster[k] = world_from_cam * m.cam_from_cluster[k];
}

TEST(EstimateSanity, TrueClusterPosesAreAllKept) {
  const Scene s = MakeScene();
  MotionEstimate e = WithTrueClusters(s);
  ASSERT_GE(e.clusters.size(), 1u);
  size_t poses = 0;
  for (const ClusterMotion& m : e.clusters) poses += m.frames.size();
  EXPECT_EQ(DropImplausibleClusterPoses(&e, s.seq.observations, s.seq.camera, {}), 0);
  size_t after = 0;
  for (const ClusterMotion& m : e.clusters) after += m.frames.size();
  EXPECT_EQ(after, poses);
}

TEST(EstimateSanity, AClusterPoseFarBeyondItsMeasuredDepthsIsLeftOutAndTheRestKept) {
  // Generated outdoor seed 4 online had a car posed 37 km away in one frame while its 18
  // observations there measured under 50 m; the map stitched it into its trajectory.
  const Scene s = MakeScene();
  MotionEstimate e = WithTrueClusters(s);
  ASSERT_GE(e.clusters[0].frames.size(), 3u);
  const ClusterMotion before = e.clusters[0];
  PushAway(&e, 0, 1, 1000.0);
  const MotionEstimate pushed = e;
  EXPECT_EQ(DropImplausibleClusterPoses(&e, s.seq.observations, s.seq.camera, {}), 1);
  ASSERT_EQ(e.clusters[0].frames.size(), before.frames.size() - 1);
  EXPECT_EQ(e.clusters[0].frames[0], before.frames[0]);
  EXPECT_EQ(e.clusters[0].frames[1], before.frames[2]);
  // Off: nothing is dropped.
  MotionEstimate off = pushed;
  EstimateSanityOptions o;
  o.max_cluster_depth_ratio = 0;
  EXPECT_EQ(DropImplausibleClusterPoses(&off, s.seq.observations, s.seq.camera, o), 0);
  // A pose behind the camera is absurd too.
  MotionEstimate behind = WithTrueClusters(s);
  PushAway(&behind, 0, 0, -1000.0);
  EXPECT_EQ(DropImplausibleClusterPoses(&behind, s.seq.observations, s.seq.camera, {}), 1);
}

TEST(EstimateSanity, AClusterWithEveryPoseAbsurdIsRemovedWithItsLabels) {
  const Scene s = MakeScene();
  MotionEstimate e = WithTrueClusters(s);
  const int label = e.clusters[0].cluster;
  const size_t n = e.clusters[0].frames.size();
  for (size_t k = 0; k < n; ++k) PushAway(&e, 0, k, 1000.0);
  EXPECT_EQ(DropImplausibleClusterPoses(&e, s.seq.observations, s.seq.camera, {}),
            static_cast<int>(n));
  for (const ClusterMotion& m : e.clusters) EXPECT_NE(m.cluster, label);
  for (size_t i = 0; i < e.landmark_cluster.size(); ++i) {
    EXPECT_NE(e.landmark_cluster[i], label) << i;
    if (s.seq.landmark_object[i] == label) EXPECT_EQ(e.landmark_cluster[i], -1) << i;
  }
}

TEST(EstimateSanity, ClusterDepthRatioCheckNamesTheField) {
  EstimateSanityOptions o;
  o.max_cluster_depth_ratio = 0.5;
  try {
    o.Check();
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_cluster_depth_ratio"), std::string::npos);
  }
}

}  // namespace
}  // namespace cslam
