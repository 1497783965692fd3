#include "system/render/snapshot_renderer.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "system/draw/cluster_colors.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

using testing::ColourNear;

StereoCamera Camera() {
  StereoCamera cam;
  cam.fx = cam.fy = 300;
  cam.cx = 160;
  cam.cy = 120;
  cam.baseline = 0.5;
  cam.width = 320;
  cam.height = 240;
  return cam;
}

// Four separated groups of points in front of the camera, one per cluster (-1, 0, 1, 2),
// expressed in the camera frame.
std::vector<RenderPoint> PointsInCamera() {
  std::vector<RenderPoint> points;
  const struct { int cluster; double x, z; } groups[] = {{1, -6, 12}, {2, 6, 14}, {0, 0, 25}, {-1, -2, 6}};
  for (const auto& g : groups)
    for (int i = 0; i < 3; ++i) points.push_back({{g.x + 1.5 * i, -1.0 + 0.5 * i, g.z}, g.cluster});
  return points;
}

void CheckPointsAppear(const Pose& world_from_cam) {
  SnapshotOptions options;
  options.width = 640;
  options.height = 400;
  std::vector<RenderPoint> points = PointsInCamera();
  for (auto& p : points) p.p = world_from_cam * p.p;
  const cv::Mat image = RenderSnapshot(points, world_from_cam, Camera(), {}, options);
  testing::MaybeSave(image, "snapshot_points.png");
  ASSERT_EQ(image.size(), cv::Size(640, 400));
  const RenderView view = SnapshotView(world_from_cam, options);
  for (const auto& p : points) {
    Eigen::Vector2d px;
    ASSERT_TRUE(view.Project(p.p, &px));
    ASSERT_FALSE(px.x() < 220 && px.y() < 160) << "test point under the legend";
    // A 6 px dot: its centre pixel has the cluster colour.
    EXPECT_TRUE(ColourNear(image, px, BgrForCluster(p.cluster), 0, 25))
        << "cluster " << p.cluster << " at " << px.transpose();
    // A pixel well away from the dot is not in that colour (greys also occur on the
    // anti-aliased edges of black lines, so only moving clusters are checked).
    if (p.cluster >= 1) {
      EXPECT_FALSE(ColourNear(image, px + Eigen::Vector2d(0, 12), BgrForCluster(p.cluster), 0, 12))
          << "cluster " << p.cluster << " at " << px.transpose();
    }
  }
  // The frustum apex (the camera centre) is drawn in black.
  Eigen::Vector2d apex;
  ASSERT_TRUE(view.Project(world_from_cam.translation(), &apex));
  EXPECT_TRUE(ColourNear(image, apex, {0, 0, 0}, 2, 90));
  // Not blank: white background plus a decent number of other pixels.
  const int white = testing::CountColour(image, {255, 255, 255}, 3);
  EXPECT_LT(white, 640 * 400 - 2000);
  EXPECT_GT(white, 640 * 400 / 2);
}

TEST(SnapshotRenderer, ClusterColoursAppearWhereThePointsProject) {
  CheckPointsAppear(Pose::Identity());
}

TEST(SnapshotRenderer, FollowsTheCameraPose) {
  Pose world_from_cam = Pose::Identity();
  world_from_cam.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                            Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).toRotationMatrix();
  world_from_cam.translation() = Eigen::Vector3d(20, -1, 35);
  CheckPointsAppear(world_from_cam);
}

TEST(SnapshotRenderer, ViewIsBehindAndAboveTheCamera) {
  SnapshotOptions options;
  const RenderView view = SnapshotView(Pose::Identity(), options);
  const Eigen::Vector3d eye = view.view_from_world.inverse().translation();
  EXPECT_LT(eye.z(), 0.0);  // behind
  EXPECT_LT(eye.y(), 0.0);  // above (y is down)
  // The look-at point is at the image centre and the camera is below it in the picture.
  Eigen::Vector2d target, camera;
  ASSERT_TRUE(view.Project({0, 0, options.look_ahead_m}, &target));
  EXPECT_NEAR(target.x(), view.cx, 1e-6);
  EXPECT_NEAR(target.y(), view.cy, 1e-6);
  ASSERT_TRUE(view.Project({0, 0, 0}, &camera));
  EXPECT_GT(camera.y(), target.y());
}

TEST(SnapshotRenderer, DrawsRecentTrajectories) {
  SnapshotOptions options;
  options.width = 640;
  options.height = 400;
  RenderTrajectory track{"cluster 3", {}, 3, false};
  for (int i = 0; i <= 20; ++i) track.positions.emplace_back(3.0, 0.0, 5.0 + i);
  const cv::Mat image = RenderSnapshot({}, Pose::Identity(), Camera(), {track}, options);
  testing::MaybeSave(image, "snapshot_trajectory.png");
  const RenderView view = SnapshotView(Pose::Identity(), options);
  for (int i = 2; i <= 18; i += 4) {
    Eigen::Vector2d px;
    ASSERT_TRUE(view.Project(track.positions[i], &px));
    EXPECT_TRUE(ColourNear(image, px, BgrForCluster(3), 1, 50)) << px.transpose();
  }
}

TEST(SnapshotRenderer, OptionsLoadEveryKeyFromYaml) {
  OptionsReader reader = OptionsReader::FromString(
      "width: 800\nheight: 500\nhorizontal_fov_deg: 60\nback_m: 3\nup_m: 2\n"
      "look_ahead_m: 9\nfar_m: 90\nlandmark_size_px: 4\ndense_point_size_px: 1.5\n"
      "frustum_depth_m: 1\nground_below_m: 0\ngrid_step_m: 2\ngrid_extent_m: 20\n"
      "supersampling: 3\ndense: {num_disparities: 64, block_size: 7, min_depth_m: 2,\n"
      "  max_depth_m: 25, voxel_size_m: 0.1, max_assign_distance_m: 1}\n",
      "test.yaml");
  SnapshotOptions options;
  EXPECT_NO_THROW(reader.LoadInto(&options));
  EXPECT_NO_THROW(options.Check());
  EXPECT_EQ(options.width, 800);
  EXPECT_EQ(options.supersampling, 3);
  EXPECT_DOUBLE_EQ(options.dense_point_size_px, 1.5);
  EXPECT_EQ(options.dense.block_size, 7);
  EXPECT_DOUBLE_EQ(options.dense.max_assign_distance_m, 1.0);
}

TEST(SnapshotRenderer, BadOptionsAreConfigErrors) {
  SnapshotOptions options;
  options.horizontal_fov_deg = 0;
  EXPECT_THROW(RenderSnapshot({}, Pose::Identity(), Camera(), {}, options), ConfigError);
  options = SnapshotOptions();
  options.dense.num_disparities = 50;
  EXPECT_THROW(options.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
