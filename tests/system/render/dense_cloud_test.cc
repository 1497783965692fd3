#include "system/render/dense_cloud.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "system/draw/cluster_colors.h"
#include "system/render/snapshot_renderer.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

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

// A fronto-parallel textured wall at disparity `d` px: right(u) = left(u + d).
void WallPair(int d, cv::Mat* left, cv::Mat* right) {
  cv::Mat texture(240, 320 + d, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  *left = texture(cv::Rect(0, 0, 320, 240)).clone();
  *right = texture(cv::Rect(d, 0, 320, 240)).clone();
}

Pose SomePose() {
  Pose world_from_cam = Pose::Identity();
  world_from_cam.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  world_from_cam.translation() = Eigen::Vector3d(10, 0.5, 5);
  return world_from_cam;
}

TEST(DenseCloud, StereoPointsLieOnTheWallAndTakeTheNearestClusteredLandmark) {
  cv::Mat left, right;
  WallPair(20, &left, &right);  // depth = 300 * 0.5 / 20 = 7.5 m
  const Pose world_from_cam = SomePose();
  std::vector<RenderPoint> landmarks;
  for (double y = -2; y <= 2; y += 1) {
    for (double x = -3.5; x < 0; x += 1) landmarks.push_back({world_from_cam * Eigen::Vector3d(x, y, 7.5), 1});
    // Cluster 2 floats 5 m behind the wall: too far to claim any wall point.
    for (double x = 0.5; x < 4; x += 1) landmarks.push_back({world_from_cam * Eigen::Vector3d(x, y, 12.5), 2});
  }
  landmarks.push_back({world_from_cam * Eigen::Vector3d(2, 0, 7.5), -1});  // unclustered: ignored
  DenseCloudOptions options;
  options.num_disparities = 32;
  DenseCloudStats stats;
  const auto dense = LabelDenseCloud(left, right, Camera(), world_from_cam, landmarks, options, &stats);

  // Most pixels right of the disparity search border match.
  EXPECT_GT(stats.stereo_points, 0.6 * (320 - 32) * 240);
  EXPECT_EQ(stats.downsampled_points, static_cast<int>(dense.size()));
  EXPECT_LT(dense.size(), static_cast<std::size_t>(stats.stereo_points) / 5);  // the voxel grid thins
  int on_wall = 0, labelled_1 = 0, unlabelled = 0;
  for (const auto& d : dense) {
    const Eigen::Vector3d p_in_cam = world_from_cam.inverse() * d.p;
    on_wall += std::abs(p_in_cam.z() - 7.5) < 0.2;
    // Brute-force nearest clustered landmark decides the expected label.
    double best = std::numeric_limits<double>::infinity();
    int expected = -1;
    for (const auto& l : landmarks) {
      if (l.cluster < 0) continue;
      const double dist = (l.p - d.p).norm();
      if (dist < best) {
        best = dist;
        expected = l.cluster;
      }
    }
    if (best > options.max_assign_distance_m) expected = -1;
    // Points within a hair of the assignment boundary may go either way in float precision.
    if (std::abs(best - options.max_assign_distance_m) > 1e-3) {
      EXPECT_EQ(d.cluster, expected);
    }
    labelled_1 += d.cluster == 1;
    unlabelled += d.cluster == -1;
  }
  EXPECT_GT(on_wall, 0.95 * dense.size());
  EXPECT_GT(labelled_1, 100);
  EXPECT_GT(unlabelled, 100);  // the right half of the wall is far from cluster 2
  EXPECT_EQ(stats.labelled_points, labelled_1);
}

TEST(DenseCloud, MismatchedImagesAreInputErrors) {
  cv::Mat left, right;
  WallPair(10, &left, &right);
  EXPECT_THROW(LabelDenseCloud(left, right(cv::Rect(0, 0, 100, 100)), Camera(), Pose::Identity(), {}, {}),
               InputError);
  StereoCamera other = Camera();
  other.width = 640;
  EXPECT_THROW(LabelDenseCloud(left, right, other, Pose::Identity(), {}, {}), InputError);
}

// A real KITTI frame: dense points near "landmarks" of a pretend cluster in the middle of the
// road take its colour in the dense snapshot.
TEST(DenseCloud, DenseSnapshotOfAKittiFrame) {
  const char* env = std::getenv("CSLAM_SHARED_DATA");  // overrides the build-time path
  const std::string dir = std::string(env ? env : CSLAM_SHARED_DATA_DIR) +
                          "/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync/";
  const cv::Mat left = cv::imread(dir + "image_00/data/0000000000.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(dir + "image_01/data/0000000000.png", cv::IMREAD_GRAYSCALE);
  if (left.empty() || right.empty()) GTEST_SKIP() << "KITTI raw frame not found under " << dir;
  StereoCamera cam;  // calib_cam_to_cam.txt, P_rect_00 and P_rect_01
  cam.fx = cam.fy = 721.5377;
  cam.cx = 609.5593;
  cam.cy = 172.8540;
  cam.baseline = 387.5744 / 721.5377;
  cam.width = left.cols;
  cam.height = left.rows;
  // Sparse landmarks: a coarse unlabelled dense cloud, every 15th point, the middle block
  // 8-20 m ahead called cluster 1 and the rest static.
  DenseCloudOptions coarse;
  coarse.voxel_size_m = 0.5;
  std::vector<RenderPoint> landmarks = LabelDenseCloud(left, right, cam, Pose::Identity(), {}, coarse);
  std::vector<RenderPoint> sparse;
  for (std::size_t i = 0; i < landmarks.size(); i += 15) {
    RenderPoint l = landmarks[i];
    l.cluster = (std::abs(l.p.x()) < 3 && l.p.z() > 8 && l.p.z() < 20) ? 1 : 0;
    sparse.push_back(l);
  }
  ASSERT_GT(sparse.size(), 50u);
  SnapshotOptions options;
  const cv::Mat image =
      RenderDenseSnapshot(sparse, Pose::Identity(), cam, {}, left, right, options);
  testing::MaybeSave(image, "snapshot_dense_kitti.png");
  EXPECT_EQ(image.size(), cv::Size(options.width, options.height));
  EXPECT_GT(testing::CountColour(image, BgrForCluster(1), 30), 500);
  EXPECT_GT(testing::CountColour(image, BgrForCluster(0), 20), 2000);
}

}  // namespace
}  // namespace cslam
