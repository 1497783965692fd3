#include "system/run/run_trajectories.h"

#include <gtest/gtest.h>

#include "tests/support/matchers.h"

namespace cslam {
namespace {

Pose Shifted(double x) {
  Pose p = Pose::Identity();
  p.translation().x() = x;
  return p;
}

// One window of three frames: the camera moves 1 m per frame, cluster 1 is seen in frames
// 1 and 2 and moves 2 m per frame.
MotionEstimate OneWindow() {
  MotionEstimate e;
  e.range = {0, 3};
  for (int f = 0; f < 3; ++f) e.world_from_cam.push_back(Shifted(f));
  e.landmark_cluster = {0, 1, 1, 1};
  e.landmark_in_cluster = {{0, 0, 10}, {1, 0, 10}, {0, 1, 10}, {0, 0, 11}};
  ClusterMotion m;
  m.cluster = 1;
  for (int f = 1; f < 3; ++f) {
    m.frames.push_back(f);
    m.world_from_cluster.push_back(Shifted(2.0 * f));
    m.cam_from_cluster.push_back(Shifted(f).inverse() * Shifted(2.0 * f));
  }
  e.clusters.push_back(m);
  return e;
}

TEST(RunTrajectories, HoldTheMapsPosesWithTheirFramesAndTimestamps) {
  MapState map;
  map.Integrate(OneWindow());
  // Two timestamps for three frames: the third gets the 10 Hz default.
  const RunTrajectories t = BuildRunTrajectories(map, {0.0, 0.05});
  EXPECT_EQ(t.camera.frames, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(t.camera.timestamps, (std::vector<double>{0.0, 0.05, 0.2}));
  for (int f = 0; f < 3; ++f)
    EXPECT_TRUE(testing::PoseNear(t.camera.poses[f], Shifted(f), 1e-12, 1e-12)) << f;
  ASSERT_EQ(t.clusters.size(), 1u);
  const Trajectory& c = t.clusters.begin()->second;
  EXPECT_EQ(c.frames, (std::vector<int>{1, 2}));
  EXPECT_NEAR((c.poses[1].translation() - c.poses[0].translation()).x(), 2.0, 1e-12);
}

TEST(RunTrajectories, AnEmptyMapHasNone) {
  const RunTrajectories t = BuildRunTrajectories(MapState{}, {});
  EXPECT_EQ(t.camera.size(), 0u);
  EXPECT_TRUE(t.clusters.empty());
}

}  // namespace
}  // namespace cslam
