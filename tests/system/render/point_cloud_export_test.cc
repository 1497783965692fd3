#include "system/render/point_cloud_export.h"

#include <gtest/gtest.h>
#include <pcl/io/auto_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/draw/cluster_colors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

TEST(PointCloudExport, PlyAndPcdRoundTripPointsAndClusterColours) {
  const fs::path dir = fs::temp_directory_path() / "cslam_cloud_test";
  fs::remove_all(dir);
  std::vector<RenderPoint> points;
  for (int i = 0; i < 50; ++i)
    points.push_back({{0.25 * i, -1.5 + 0.01 * i, 3.0 + i * i * 0.1}, i % 5 - 1});
  points.push_back({{std::nan(""), 0, 0}, 1});  // skipped
  const std::string ply = (dir / "out" / "landmarks.ply").string();
  const std::string pcd = (dir / "out" / "landmarks.pcd").string();
  WriteLandmarkClouds(points, ply, pcd);
  EXPECT_FALSE(fs::exists(TemporaryPathFor(ply)));
  EXPECT_FALSE(fs::exists(TemporaryPathFor(pcd)));

  for (const std::string& path : {ply, pcd}) {
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    ASSERT_EQ(pcl::io::load(path, cloud), 0) << path;
    ASSERT_EQ(cloud.size(), 50u) << path;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const auto& q = cloud[i];
      EXPECT_NEAR(q.x, points[i].p.x(), 1e-5 * (1 + std::abs(points[i].p.x())));
      EXPECT_NEAR(q.y, points[i].p.y(), 1e-5 * (1 + std::abs(points[i].p.y())));
      EXPECT_NEAR(q.z, points[i].p.z(), 1e-5 * (1 + std::abs(points[i].p.z())));
      const cv::Vec3b rgb = ColorForCluster(points[i].cluster);
      EXPECT_EQ(q.r, rgb[0]) << path << " point " << i;
      EXPECT_EQ(q.g, rgb[1]) << path << " point " << i;
      EXPECT_EQ(q.b, rgb[2]) << path << " point " << i;
    }
  }
  fs::remove_all(dir);
}

TEST(PointCloudExport, NoPointsGiveValidEmptyFiles) {
  // A run stopped before its first window (a corrupt image, Ctrl-C) has no landmarks; its
  // clouds must still be files a reader accepts, not an output error.
  const fs::path dir = fs::temp_directory_path() / "cslam_cloud_empty_test";
  fs::remove_all(dir);
  const std::string ply = (dir / "landmarks.ply").string(), pcd = (dir / "landmarks.pcd").string();
  WriteLandmarkClouds({{{std::nan(""), 0, 0}, 1}}, ply, pcd);
  for (const std::string& path : {ply, pcd}) {
    ASSERT_TRUE(fs::exists(path)) << path;
    EXPECT_FALSE(fs::exists(TemporaryPathFor(path)));
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    pcl::PCLPointCloud2 blob;
    EXPECT_EQ(pcl::io::load(path, blob), 0) << path;
    EXPECT_EQ(blob.width * blob.height, 0u) << path;
  }
  fs::remove_all(dir);
}

TEST(PointCloudExport, UnwritablePathIsAnOutputErrorNamingTheFile) {
  const fs::path blocker = fs::temp_directory_path() / "cslam_cloud_blocker";
  { std::ofstream(blocker) << "x"; }
  const std::string ply = (blocker / "landmarks.ply").string();
  try {
    WriteLandmarkClouds({{{1, 2, 3}, 1}}, ply, (blocker / "landmarks.pcd").string());
    ADD_FAILURE() << "expected an OutputError";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(ply), std::string::npos) << e.what();
  }
  fs::remove(blocker);
}

}  // namespace
}  // namespace cslam
