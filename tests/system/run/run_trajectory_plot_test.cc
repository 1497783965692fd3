#include "system/run/run_trajectory_plot.h"

#include <gtest/gtest.h>

#include "system/draw/cluster_colors.h"
#include "system/render/trajectory_plot.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

Pose At(double x, double z, double yaw = 0.0) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, 0.0, z);
  return p;
}

/// The camera drives 20 m along z; cluster 2 (frames 3..9) drives beside it, turning.
RunOutputs Outputs() {
  RunOutputs o;
  for (int f = 0; f < 10; ++f) {
    o.camera.frames.push_back(f);
    o.camera.poses.push_back(At(0.0, 2.0 * f));
    o.gt_camera.frames.push_back(f);
    o.gt_camera.poses.push_back(At(0.3, 2.0 * f));
  }
  Trajectory& c = o.clusters[2];
  for (int f = 3; f < 10; ++f) {
    c.frames.push_back(f);
    c.poses.push_back(At(5.0, 10.0 + 1.5 * f, 0.1 * f));
  }
  return o;
}

/// Draws every cluster with a line: the tests below pin what is drawn and how, not the filter.
constexpr TrajectoryPlotOptions kAll{.min_poses = 2, .min_landmarks = 0};

TEST(RunTrajectoryPlot, GroundTruthDashedThenCameraThenClusters) {
  const auto lines = RunTrajectoryPlotLines(Outputs(), kAll);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_TRUE(lines[0].dashed);
  EXPECT_EQ(lines[0].cluster, -1);
  EXPECT_EQ(lines[0].positions[4], Eigen::Vector3d(0.3, 0, 8));
  EXPECT_FALSE(lines[1].dashed);
  EXPECT_EQ(lines[1].label, "camera");
  EXPECT_EQ(lines[1].positions.size(), 10u);
  EXPECT_EQ(lines[2].cluster, 2);
  EXPECT_EQ(lines[2].label, "object 2 (0 points, frames 3-9)");
}

TEST(RunTrajectoryPlot, FramesWithoutAPoseBreakTheLineInsteadOfBridgingIt) {
  RunOutputs o = Outputs();
  // The object is out of sight over frames 6..8 (behind a parked van), the camera lost at 5.
  Trajectory& c = o.clusters.at(2);
  c.frames = {3, 4, 5, 9};
  c.poses.resize(4);
  o.camera.frames.erase(o.camera.frames.begin() + 5);
  o.camera.poses.erase(o.camera.poses.begin() + 5);
  const auto lines = RunTrajectoryPlotLines(o, kAll);
  ASSERT_EQ(lines.size(), 3u);
  const auto& cam = lines[1].positions;
  ASSERT_EQ(cam.size(), 10u);  // 9 poses and one break
  for (size_t k = 0; k < cam.size(); ++k) EXPECT_EQ(cam[k].allFinite(), k != 5) << k;
  const auto& obj = lines[2].positions;
  ASSERT_EQ(obj.size(), 5u);
  for (size_t k = 0; k < obj.size(); ++k) EXPECT_EQ(obj[k].allFinite(), k != 3) << k;
  EXPECT_EQ(obj[4], c.poses[3].translation());
}

TEST(RunTrajectoryPlot, ClusterIsDrawnAsItsLandmarksCentroidFromTheirWorldPositions) {
  RunOutputs o = Outputs();
  const Trajectory& c = o.clusters.at(2);
  // Two landmarks at (1,0,0) and (3,0,2) in the cluster frame: centroid (2,0,1). One was last
  // seen at frame 5 (placed with that pose), the other at frame 12, where the cluster has no
  // pose (placed with its last pose, frame 9), as the run writer places them.
  o.landmarks.push_back({1, 2, 3, 5, c.poses[2] * Eigen::Vector3d(1, 0, 0)});
  o.landmarks.push_back({2, 2, 4, 12, c.poses.back() * Eigen::Vector3d(3, 0, 2)});
  o.landmarks.push_back({3, 0, 0, 9, Eigen::Vector3d(50, 0, 50)});  // static: not in any centroid
  const auto lines = RunTrajectoryPlotLines(o, kAll);
  ASSERT_EQ(lines.size(), 3u);
  ASSERT_EQ(lines[2].positions.size(), c.size());
  for (size_t k = 0; k < c.size(); ++k)
    EXPECT_TRUE(lines[2].positions[k].isApprox(c.poses[k] * Eigen::Vector3d(2, 0, 1), 1e-12))
        << "pose " << k << ": " << lines[2].positions[k].transpose();
}

TEST(RunTrajectoryPlot, ClusterFarBeyondTheCameraIsLeftOut) {
  RunOutputs o = Outputs();
  Trajectory& far = o.clusters[4];
  far.frames = {0, 1};
  far.poses = {At(0.0, 5.0), At(0.0, 5000.0)};
  const auto lines = RunTrajectoryPlotLines(o, kAll);
  for (const auto& l : lines) EXPECT_NE(l.cluster, 4);
  EXPECT_EQ(lines.size(), 3u);
}

TEST(RunTrajectoryPlot, ClusterWithOnePoseIsNotALine) {
  RunOutputs o = Outputs();
  o.clusters[5].frames = {2};
  o.clusters[5].poses = {At(1.0, 1.0)};
  for (const auto& l : RunTrajectoryPlotLines(o, kAll)) EXPECT_NE(l.cluster, 5);
}

TEST(RunTrajectoryPlot, PictureShowsTheClusterInItsColour) {
  const RunOutputs o = Outputs();
  const cv::Mat image = RenderRunTrajectoryPlot(o, 800, 600, kAll);
  testing::MaybeSave(image, "run_trajectory_plot.png");
  ASSERT_EQ(image.size(), cv::Size(800, 600));
  const TopViewLayout layout = ComputeTopViewLayout(RunTrajectoryPlotLines(o, kAll), 800, 600);
  // Without landmarks the centroid is the cluster frame's origin.
  EXPECT_TRUE(testing::ColourNear(image, layout.ToPixel(o.clusters.at(2).poses[3].translation()),
                                  BgrForCluster(2), 1, 60));
  EXPECT_TRUE(testing::ColourNear(image, layout.ToPixel(Eigen::Vector3d(0, 0, 12)), {0, 0, 0}, 1, 70));
  EXPECT_EQ(testing::CountColour(image, BgrForCluster(5), 30), 0);
}

/// Cluster `id` with `poses` poses along x = x0 and `landmarks` landmarks at its origin.
void AddCluster(RunOutputs* o, int id, int poses, int landmarks, double x0) {
  Trajectory& c = o->clusters[id];
  for (int f = 0; f < poses; ++f) {
    c.frames.push_back(f);
    c.poses.push_back(At(x0, 1.0 * f));
  }
  for (int k = 0; k < landmarks; ++k)
    o->landmarks.push_back({1000 * id + k, id, 0, poses - 1, c.poses.back().translation()});
}

TEST(RunTrajectoryPlot, SmallOrShortClustersAreCountedNotDrawnAndTheBiggestComesFirst) {
  RunOutputs o = Outputs();  // cluster 2: 7 poses, no landmarks
  AddCluster(&o, 3, 12, 20, 3.0);
  AddCluster(&o, 4, 12, 40, 4.0);
  AddCluster(&o, 6, 12, 5, 6.0);  // too few landmarks
  AddCluster(&o, 7, 4, 50, 7.0);  // too few poses
  const auto lines = RunTrajectoryPlotLines(o, {.min_poses = 10, .min_landmarks = 15});
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[2].cluster, 4);
  EXPECT_EQ(lines[3].cluster, 3);
  EXPECT_EQ(lines[4].cluster, kUndrawnClusters);
  EXPECT_TRUE(lines[4].positions.empty());
  EXPECT_EQ(lines[4].label, "+ 3 small clusters not drawn (< 15 points or < 10 poses)");
  const cv::Mat image = RenderRunTrajectoryPlot(o, 800, 600, {.min_poses = 10, .min_landmarks = 15});
  EXPECT_GT(testing::CountColour(image, BgrForCluster(4), 30), 0);
  EXPECT_EQ(testing::CountColour(image, BgrForCluster(7), 30), 0);
}

TEST(PlacingPoseIndex, LastFrameWhenTheClusterHasAPoseThereElseItsLastPose) {
  Trajectory c;
  c.frames = {2, 3, 5};
  c.poses.assign(3, Pose::Identity());
  EXPECT_EQ(PlacingPoseIndex(c, 3), 1);
  EXPECT_EQ(PlacingPoseIndex(c, 5), 2);
  EXPECT_EQ(PlacingPoseIndex(c, 4), 2);
  EXPECT_EQ(PlacingPoseIndex(c, 9), 2);
  EXPECT_EQ(PlacingPoseIndex(Trajectory{}, 3), -1);
}

}  // namespace
}  // namespace cslam
