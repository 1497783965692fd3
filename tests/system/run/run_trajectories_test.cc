#include "system/run/run_trajectories.h"

#include <gtest/gtest.h>

#include "tests/support/poses.h"

namespace cslam {
namespace {

using testing::Translation;

// One window over frames [0, 10): the camera drives along z, landmarks 0..3 are static and
// 4..7 ride a body that slides along x.
MapState MapWithOneMovingBody() {
  MotionEstimate e;
  e.range = {0, 10};
  for (int f = 0; f < 10; ++f) e.world_from_cam.push_back(Translation(0, 0, f));
  for (int l = 0; l < 8; ++l) {
    e.landmark_cluster.push_back(l >= 4 ? 1 : 0);
    e.landmark_in_cluster.emplace_back(l % 3 - 1.0, l % 2 - 0.5, 10.0 + l);
  }
  ClusterMotion body;
  body.cluster = 1;
  for (int f = 0; f < 10; ++f) {
    body.frames.push_back(f);
    body.world_from_cluster.push_back(Translation(0.5 * f, 0, 0));
    body.cam_from_cluster.push_back(e.world_from_cam[f].inverse() * body.world_from_cluster.back());
  }
  e.clusters.push_back(body);
  MapState map;
  map.Integrate(e);
  return map;
}

TEST(RunTrajectories, HoldTheMapsCameraAndClusterPosesWithTheirFramesAndTimestamps) {
  const MapState map = MapWithOneMovingBody();
  // Fewer timestamps than frames: the rest are 0.1 s apart by frame index.
  const RunTrajectories t = BuildRunTrajectories(map, {10.0, 10.1, 10.2, 10.3});
  ASSERT_EQ(map.clusters().size(), 1u);
  ASSERT_EQ(t.camera.size(), 10u);
  EXPECT_EQ(t.camera.frames, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_DOUBLE_EQ(t.camera.timestamps[3], 10.3);
  EXPECT_DOUBLE_EQ(t.camera.timestamps[5], 0.5);
  for (size_t k = 0; k < t.camera.size(); ++k)
    EXPECT_TRUE(t.camera.poses[k].isApprox(*map.world_from_cam()[t.camera.frames[k]])) << k;

  ASSERT_EQ(t.clusters.size(), map.clusters().size());
  for (const auto& [id, cluster] : map.clusters()) {
    const Trajectory& c = t.clusters.at(id);
    ASSERT_EQ(c.size(), cluster.world_from_cluster.size());
    size_t k = 0;
    for (const auto& [f, pose] : cluster.world_from_cluster) {
      EXPECT_EQ(c.frames[k], f);
      EXPECT_DOUBLE_EQ(c.timestamps[k], t.camera.timestamps[f]);
      EXPECT_TRUE(c.poses[k].isApprox(pose));
      ++k;
    }
  }
}

}  // namespace
}  // namespace cslam
