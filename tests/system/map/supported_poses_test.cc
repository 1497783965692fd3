#include "system/map/supported_poses.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/rigid.h"
#include "tests/support/matchers.h"
#include "tests/support/poses.h"

namespace cslam {
namespace {

using testing::Translation;

// One window over frames 0..29: a static world and a car that drives 0.5 m per frame. The
// window placed the car at all 30 frames, but of its landmarks only `late` are seen from
// frame 12 on and `early` (fewer than three) from frame 0 to 15.
struct Scene {
  MapState map;
  TrackletTable table;
  std::vector<Pose> world_from_car;
};

Scene CarSeenLate(int early, int late) {
  Scene s;
  MotionEstimate e;
  e.range = {0, 30};
  ClusterMotion car;
  car.cluster = 1;
  for (int f = 0; f < 30; ++f) {
    e.world_from_cam.push_back(Translation(0, 0, f));
    s.world_from_car.push_back(Translation(2, 0, 10 + 1.5 * f));
    car.frames.push_back(f);
    car.world_from_cluster.push_back(s.world_from_car.back());
    car.cam_from_cluster.push_back(e.world_from_cam.back().inverse() * s.world_from_car.back());
  }
  e.clusters.push_back(car);
  const auto add = [&](int cluster, const Eigen::Vector3d& p, int first, int last) {
    const int l = s.table.NewLandmark();
    e.landmark_cluster.push_back(cluster);
    e.landmark_in_cluster.push_back(p);
    for (int f = first; f <= last; ++f)
      s.table.Add(l, f, Eigen::Vector3d(600, 180, 590), Eigen::Matrix3d::Identity());
  };
  for (int i = 0; i < 10; ++i) add(0, Eigen::Vector3d(i - 5.0, 1, 20 + i), 0, 29);
  for (int i = 0; i < early; ++i) add(1, Eigen::Vector3d(-1, 0.2 * i, -2), 0, 15);
  for (int i = 0; i < late; ++i) add(1, Eigen::Vector3d(0.3 * i, -0.5, 2), 12, 29);
  s.map.Integrate(e);
  return s;
}

TEST(SupportedPoses, ACarsPosesWhereFewerThanThreeOfItsPointsAreSeenAreDropped) {
  Scene s = CarSeenLate(2, 6);
  ASSERT_EQ(s.map.clusters().at(1).world_from_cluster.size(), 30u);
  const SupportedPoses result = KeepSupportedPoses(&s.map, s.table, 3);
  EXPECT_EQ(result.dropped, 12);  // frames 0..11: only the two early points
  EXPECT_EQ(result.released, 0);
  const MapCluster& car = s.map.clusters().at(1);
  ASSERT_EQ(car.world_from_cluster.size(), 18u);
  EXPECT_EQ(car.world_from_cluster.begin()->first, 12);
  EXPECT_EQ(car.world_from_cluster.rbegin()->first, 29);
  for (const auto& [f, pose] : car.world_from_cluster)
    EXPECT_TRUE(testing::PoseNear(pose, s.world_from_car[f], 1e-12, 1e-12)) << f;
  EXPECT_EQ(s.map.ClusterOf(10), 1);  // the early points stay the car's
}

TEST(SupportedPoses, ThreePointsAtEveryFrameKeepEveryPose) {
  Scene s = CarSeenLate(3, 6);
  EXPECT_EQ(KeepSupportedPoses(&s.map, s.table, 3).dropped, 0);
  EXPECT_EQ(s.map.clusters().at(1).world_from_cluster.size(), 30u);
}

TEST(SupportedPoses, AClusterNeverSeenByThreePointsAtOnceIsReleased) {
  Scene s = CarSeenLate(2, 2);  // two early, two late: frames 12..15 see four
  EXPECT_EQ(KeepSupportedPoses(&s.map, s.table, 5).released, 1);
  EXPECT_EQ(s.map.clusters().count(1), 0u);
  EXPECT_EQ(s.map.ClusterOf(10), -1);
  EXPECT_EQ(s.map.ClusterOf(0), 0);  // the static world is untouched
}

}  // namespace
}  // namespace cslam
