#include "backend/place_split.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cslam {
namespace {

// Points along x from `start`, `step` apart: one vehicle's visible points when step is small.
std::vector<Eigen::Vector3d> Row(double start, int count, double step, double y = 0) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < count; ++i) out.emplace_back(start + i * step, y, 0.5 * (i % 3));
  return out;
}

TEST(PlaceSplit, SingleLinkageJoinsChainsAndNumbersGroupsLargestFirst) {
  std::vector<Eigen::Vector3d> points = Row(0, 5, 1.0);        // a car, 4 m long
  for (const auto& p : Row(20, 9, 3.5)) points.push_back(p);    // a chain 28 m long, 3.5 m steps
  points.emplace_back(100, 0, 0);                                // a stray point
  const std::vector<int> group = GroupsByGap(points, 4.0);
  ASSERT_EQ(group.size(), points.size());
  for (int i = 0; i < 5; ++i) EXPECT_EQ(group[i], 1) << i;      // the smaller second
  for (int i = 5; i < 14; ++i) EXPECT_EQ(group[i], 0) << i;     // one group despite its length
  EXPECT_EQ(group[14], 2);
  // At a gap below the chain's step it falls apart.
  const std::vector<int> fine = GroupsByGap(points, 3.0);
  EXPECT_NE(fine[5], fine[6]);
}

TEST(PlaceSplit, SeparatedByGapLooksAtTheNearestPair) {
  EXPECT_TRUE(SeparatedByGap(Row(0, 5, 1.0), Row(12, 5, 1.0), 4.0));    // 8 m between them
  EXPECT_FALSE(SeparatedByGap(Row(0, 5, 1.0), Row(7.5, 5, 1.0), 4.0));  // 3.5 m
  EXPECT_TRUE(SeparatedByGap({}, Row(0, 3, 1.0), 4.0));
}

// Two cars of one motion 12 m apart and a stray pair, in one cluster: the larger car keeps
// the label, the other becomes a cluster of its own with the same motion, the stray pair (too
// few to be a body) stays; a compact cluster and the static world are untouched.
TEST(PlaceSplit, AClusterOfTwoPlacesBecomesTwoClustersWithTheSameMotion) {
  MotionEstimate e;
  e.range = {0, 3};
  e.world_from_cam.assign(3, Pose::Identity());
  auto add = [&e](const std::vector<Eigen::Vector3d>& points, int label) {
    for (const auto& p : points) {
      e.landmark_cluster.push_back(label);
      e.landmark_in_cluster.push_back(p);
    }
  };
  add(Row(0, 8, 0.5), 1);                     // car A: landmarks 0..7
  add(Row(16, 6, 0.6), 1);                    // car B, 12 m behind A's last point: 8..13
  add({{40, 0, 0}, {40.5, 0, 0}}, 1);         // two strays: 14, 15
  add(Row(0, 10, 0.4, 30), 2);                // a compact cluster: 16..25
  add(Row(-50, 20, 3.0), 0);                  // static points far apart: 26..45
  for (int label : {1, 2}) {
    ClusterMotion c;
    c.cluster = label;
    c.frames = {0, 1, 2};
    for (int f = 0; f < 3; ++f) {
      Pose p = Pose::Identity();
      p.translation() = Eigen::Vector3d(label * f, 0, 0);
      c.cam_from_cluster.push_back(p);
      c.world_from_cluster.push_back(p);
    }
    e.clusters.push_back(c);
  }
  EXPECT_EQ(SplitClustersByPlace(4.0, 5, &e), 1);
  for (int l = 0; l < 8; ++l) EXPECT_EQ(e.landmark_cluster[l], 1) << l;
  for (int l = 8; l < 14; ++l) EXPECT_EQ(e.landmark_cluster[l], 3) << l;
  for (int l = 14; l < 16; ++l) {  // too few to be a body: they stay
    EXPECT_EQ(e.landmark_cluster[l], 1) << l;
    EXPECT_TRUE(e.landmark_in_cluster[l].allFinite()) << l;
  }
  for (int l = 16; l < 26; ++l) EXPECT_EQ(e.landmark_cluster[l], 2) << l;
  for (int l = 26; l < 46; ++l) EXPECT_EQ(e.landmark_cluster[l], 0) << l;
  ASSERT_EQ(e.clusters.size(), 3u);
  const ClusterMotion* b = e.FindCluster(3);
  ASSERT_NE(b, nullptr);
  ASSERT_EQ(b->frames, e.clusters[0].frames);
  for (size_t k = 0; k < b->frames.size(); ++k)
    EXPECT_TRUE(b->world_from_cluster[k].isApprox(e.clusters[0].world_from_cluster[k]));
  // Off: nothing moves.
  MotionEstimate again = e;
  EXPECT_EQ(SplitClustersByPlace(0.0, 5, &again), 0);
}

}  // namespace
}  // namespace cslam
