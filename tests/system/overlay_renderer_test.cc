#include "system/overlay_renderer.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "system/cluster_colors.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

using testing::ColourNear;

TEST(OverlayRenderer, DrawsClusterColoursAtTrackPositionsAndTrails) {
  const cv::Mat grey(120, 200, CV_8UC1, cv::Scalar(100));
  std::vector<OverlayTrack> tracks;
  tracks.push_back({1, {{20, 20}, {30, 20}, {40, 20}}});
  tracks.push_back({2, {{150, 90}}});
  tracks.push_back({0, {{60.5, 100}, {80.5, 100}}});
  tracks.push_back({-1, {{180, 20}}});
  const cv::Mat image = RenderOverlay(grey, tracks);
  testing::MaybeSave(image, "overlay_synthetic.png");
  ASSERT_EQ(image.size(), grey.size());
  ASSERT_EQ(image.type(), CV_8UC3);
  for (const auto& t : tracks)
    EXPECT_TRUE(ColourNear(image, t.trail.back(), BgrForCluster(t.cluster), 0, 10))
        << "cluster " << t.cluster;
  // The trail of cluster 1 runs from x = 20 to 40 along y = 20.
  EXPECT_TRUE(ColourNear(image, {27, 20}, BgrForCluster(1), 0, 40));
  // Untouched pixels keep the grey image.
  EXPECT_EQ(image.at<cv::Vec3b>(60, 100), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(image.at<cv::Vec3b>(30, 30), cv::Vec3b(100, 100, 100));
}

TEST(OverlayRenderer, MovingClustersAreDrawnOverStaticOnes) {
  const cv::Mat grey(40, 40, CV_8UC1, cv::Scalar(0));
  // Listed moving first, static second, at the same place: the moving colour must win.
  const cv::Mat image = RenderOverlay(grey, {{3, {{20, 20}}}, {0, {{20, 20}}}});
  EXPECT_TRUE(ColourNear(image, {20, 20}, BgrForCluster(3), 0, 10));
}

TEST(OverlayRenderer, RejectsAnEmptyImage) {
  EXPECT_THROW(RenderOverlay(cv::Mat(), {}), InputError);
}

}  // namespace
}  // namespace cslam
