#include "system/map/object_report.h"

#include <gtest/gtest.h>

namespace cslam {
namespace {

// One window of 12 frames: a camera driving along z, 10 static landmarks and three moving
// clusters: 1 with 6 landmarks posed in every frame, 2 with only 3 landmarks, 3 with 6
// landmarks posed in 5 frames only. Cluster c drives along x at c m per frame (one motion each:
// the map would merge clusters that move alike).
// `begin` shifts the window along the same drive; without `third`, the window does not find
// cluster 3 (its landmarks unlabelled).
MotionEstimate Window(int begin = 0, bool third = true) {
  MotionEstimate e;
  e.range = {begin, begin + 12};
  for (int f = begin; f < begin + 12; ++f) {
    Pose cam = Pose::Identity();
    cam.translation() = Eigen::Vector3d(0, 0, f);
    e.world_from_cam.push_back(cam);
  }
  const std::vector<int> sizes = {10, 6, 3, 6};
  for (int c = 0; c < 4; ++c)
    for (int i = 0; i < sizes[c]; ++i) {
      e.landmark_cluster.push_back(c == 3 && !third ? -1 : c);
      e.landmark_in_cluster.emplace_back(i, c, 20 + i);
    }
  for (int c = 1; c <= (third ? 3 : 2); ++c) {
    ClusterMotion m;
    m.cluster = c;
    for (int f = begin; f < begin + (c == 3 ? 5 : 12); ++f) {
      Pose body = Pose::Identity();
      body.translation() = Eigen::Vector3d(c * f, 0, 0);
      m.frames.push_back(f);
      m.world_from_cluster.push_back(body);
      m.cam_from_cluster.push_back(e.world_from_cam[f - begin].inverse() * body);
    }
    e.clusters.push_back(m);
  }
  return e;
}

TEST(ObjectReport, OnlyClustersWithEnoughLandmarksAndFramesAreReported) {
  MapState map;
  map.Integrate(Window());
  ASSERT_EQ(map.clusters().size(), 3u);
  MapStateOptions options;
  options.report_min_landmarks = 5;
  options.report_min_frames = 10;
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1}));
  options.report_min_landmarks = 3;
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1, 2}));
  options.report_min_frames = 5;
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1, 2, 3}));
}

TEST(ObjectReport, AClusterOnlyOneOfTheWindowsCoveringItFoundIsNotReported) {
  MapStateOptions options;
  options.report_min_landmarks = 3;
  options.report_min_frames = 5;
  MapState map;
  map.Integrate(Window(0));
  // One window so far (a batch run's whole-sequence solve): it covers everything once.
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1, 2, 3}));
  map.Integrate(Window(2, /*third=*/false));
  EXPECT_EQ(map.WindowsCovering(0, 4), 2);
  EXPECT_EQ(map.clusters().at(1).windows, 2);
  EXPECT_EQ(map.clusters().at(3).windows, 1);
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1, 2}));
  options.report_min_windows = 1;
  EXPECT_EQ(ReportedClusters(map, options), std::set<int>({1, 2, 3}));
}

TEST(ObjectReport, TheOthersLandmarksBecomeOutliersWhereTheirClusterWasLastSeen) {
  MapState map;
  map.Integrate(Window());
  MapStateOptions options;  // defaults: 5 landmarks, 10 frames
  EXPECT_EQ(KeepClustersHolding(&map, ReportedLandmarks(map, options)), 2);
  ASSERT_EQ(map.clusters().size(), 1u);
  EXPECT_EQ(map.clusters().begin()->first, 1);
  int outliers = 0;
  for (int l : map.Landmarks()) {
    const int c = map.ClusterOf(l);
    EXPECT_GE(c, -1);
    if (c != -1) continue;
    ++outliers;
    // Landmarks 19..24 are cluster 3's, whose last pose (frame 4) is 12 m along x.
    const std::optional<Eigen::Vector3d> p = map.WorldPosition(l, 0);
    ASSERT_TRUE(p.has_value());
    if (l >= 19) {
      const int i = l - 19;
      EXPECT_TRUE(p->isApprox(Eigen::Vector3d(i + 12, 3, 20 + i), 1e-12)) << l << ": " << p->transpose();
    }
  }
  EXPECT_EQ(outliers, 3 + 6);
}

}  // namespace
}  // namespace cslam
