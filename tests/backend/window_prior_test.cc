#include "backend/window_prior.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/backend/test_scene.h"

namespace cslam {
namespace {

using testing::MakeScene;
using testing::RandomPoints;
using testing::SyntheticCamera;
using testing::YawPose;

// A camera that accelerates and turns more and more sharply through a static street of
// points: a constant-velocity prediction from any two frames drifts away from the truth.
std::vector<Eigen::Vector3d> StreetPoints() { return RandomPoints(400, {-15, -3, 2}, {15, 2, 60}, 7); }

testing::TestScene AcceleratingStreet() {
  testing::TestBody street;
  street.points_in_body = StreetPoints();
  street.world_from_body = [](int) { return Pose::Identity(); };
  return MakeScene(SyntheticCamera(true), {street}, 20,
                   [](int t) { return YawPose(0.002 * t * t, {0.01 * t * t, 0, 0.4 * t + 0.03 * t * t}); },
                   0.5, 0.5, 11);
}

// The prior a map would give: true poses at frames [first_known, last_known], every landmark
// static at its true position.
WindowPrior PriorFrom(const testing::TestScene& s, int first_known, int last_known) {
  WindowPrior p;
  p.range = {0, static_cast<int>(s.world_from_cam.size())};
  p.world_from_cam.resize(p.range.size());
  for (int f = first_known; f <= last_known; ++f) p.world_from_cam[f] = s.world_from_cam[f];
  const int n = s.table.num_landmarks();
  p.landmark_cluster.assign(n, 0);
  p.static_point = StreetPoints();  // landmark ids follow the body's points
  p.static_point.resize(n);
  return p;
}

double TranslationError(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }

TEST(CompleteCameraPoses, FramesAfterTheKnownOnesAreRegisteredOnTheStaticLandmarks) {
  const testing::TestScene s = AcceleratingStreet();
  WindowPrior prior = PriorFrom(s, 0, 9);
  const std::vector<Pose> poses = CompleteCameraPoses(prior, s.table, s.camera, ShapeInitOptions{});
  ASSERT_EQ(poses.size(), 20u);
  for (int f = 0; f <= 9; ++f) EXPECT_TRUE(poses[f].isApprox(s.world_from_cam[f])) << f;
  // Measured: 1–3 mm on ~400 points with 0.5 px noise.
  for (int f = 10; f < 20; ++f) EXPECT_LT(TranslationError(poses[f], s.world_from_cam[f]), 0.02) << f;

  // Without static landmarks the same frames only get the prediction, which is far off: the
  // registration above is what placed them.
  prior.landmark_cluster.assign(prior.landmark_cluster.size(), -1);
  const std::vector<Pose> predicted = CompleteCameraPoses(prior, s.table, s.camera, ShapeInitOptions{});
  EXPECT_GT(TranslationError(predicted[19], s.world_from_cam[19]), 2.0);
}

TEST(CompleteCameraPoses, FramesBeforeTheKnownOnesAreRegisteredBackwards) {
  const testing::TestScene s = AcceleratingStreet();
  const WindowPrior prior = PriorFrom(s, 12, 19);
  const std::vector<Pose> poses = CompleteCameraPoses(prior, s.table, s.camera, ShapeInitOptions{});
  for (int f = 0; f < 12; ++f) EXPECT_LT(TranslationError(poses[f], s.world_from_cam[f]), 0.02) << f;
}

TEST(CompleteCameraPoses, NeedsAKnownPose) {
  const testing::TestScene s = AcceleratingStreet();
  WindowPrior prior = PriorFrom(s, 0, 0);
  prior.world_from_cam[0].reset();
  EXPECT_EQ(prior.KnownFrames(), 0);
  EXPECT_DEATH(CompleteCameraPoses(prior, s.table, s.camera, ShapeInitOptions{}), "known camera pose");
}

}  // namespace
}  // namespace cslam
