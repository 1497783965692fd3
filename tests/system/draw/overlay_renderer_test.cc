#include "system/draw/overlay_renderer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"
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

// A real KITTI frame with corners as tracks: those in the middle band are "cluster 1" with a
// trail drifting left, the rest static.
TEST(OverlayRenderer, KittiFrameWithClusteredCorners) {
  const char* env = std::getenv("CSLAM_SHARED_DATA");  // overrides the build-time path
  const std::string file = std::string(env ? env : CSLAM_SHARED_DATA_DIR) +
                           "/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync/image_00/data/"
                           "0000000010.png";
  const cv::Mat grey = cv::imread(file, cv::IMREAD_GRAYSCALE);
  if (grey.empty()) GTEST_SKIP() << "KITTI raw frame not found: " << file;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey, corners, 300, 0.01, 12);
  ASSERT_GT(corners.size(), 100u);
  std::vector<OverlayTrack> tracks;
  for (const auto& c : corners) {
    OverlayTrack t;
    t.cluster = (c.x > 500 && c.x < 750) ? 1 : 0;
    for (int k = 4; k >= 0; --k) t.trail.emplace_back(c.x + (t.cluster == 1 ? 4.0 : 1.5) * k, c.y);
    tracks.push_back(t);
  }
  const cv::Mat image = RenderOverlay(grey, tracks);
  testing::MaybeSave(image, "overlay_kitti.png");
  for (const auto& t : tracks) {
    if (t.cluster == 1) {
      EXPECT_TRUE(ColourNear(image, t.trail.back(), BgrForCluster(1), 0, 10));
    }
  }
}

TEST(OverlayRenderer, TheLegendShowsEachObjectsColourAndTheCornerLabelSitsOnWhite) {
  // Tracks far from the legend's corner, so what is in that corner is the legend's.
  const std::vector<OverlayTrack> tracks = {{0, {{500, 150}}}, {7, {{520, 160}}}, {7, {{530, 170}}}};
  cv::Mat image(200, 600, CV_8UC3, cv::Scalar(0, 0, 0));
  DrawOverlayLegend(image, tracks);
  const cv::Mat legend = image(cv::Rect(0, 0, 200, 100));
  EXPECT_GT(testing::CountColour(legend, BgrForCluster(7), 10), 10);
  EXPECT_GT(testing::CountColour(legend, BgrForCluster(0), 10), 10);
  EXPECT_EQ(testing::CountColour(legend, BgrForCluster(3), 10), 0);  // no such object
  PutCornerLabel(image, "frame 12, final estimate");
  EXPECT_GT(testing::CountColour(image(cv::Rect(350, 0, 250, 40)), {255, 255, 255}, 0), 1000);
  EXPECT_EQ(testing::CountColour(image(cv::Rect(350, 60, 250, 40)), {255, 255, 255}, 0), 0);
}

TEST(OverlayRenderer, RejectsAnEmptyImage) {
  EXPECT_THROW(RenderOverlay(cv::Mat(), {}), InputError);
}

}  // namespace
}  // namespace cslam
