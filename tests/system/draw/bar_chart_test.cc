#include "system/draw/bar_chart.h"

#include <gtest/gtest.h>

#include "system/draw/line_chart.h"

namespace cslam {
namespace {

// Rows of column x whose pixel is `bgr`.
int ColumnHeight(const cv::Mat& img, int x, const cv::Scalar& bgr) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
    n += p[0] == bgr[0] && p[1] == bgr[1] && p[2] == bgr[2];
  }
  return n;
}

// The first column (left to right) holding at least 10 pixels of `bgr`, from `from`.
int FirstColumnWith(const cv::Mat& img, const cv::Scalar& bgr, int from = 0) {
  for (int x = from; x < img.cols; ++x)
    if (ColumnHeight(img, x, bgr) >= 10) return x;
  return -1;
}

TEST(BarChart, BarHeightsAreProportionalToTheValues) {
  BarChart c;
  c.title = "ATE";
  c.categories = {"drive_a", "drive_b"};
  c.series = {{"ours", {1.0, 2.0}, SeriesColor(0)}, {"peer", {0.5, std::nullopt}, SeriesColor(1)}};
  c.y_max = 4.0;
  const cv::Mat img = RenderBarChart(c, 800, 600);
  ASSERT_EQ(img.size(), cv::Size(800, 600));
  // Ours on drive a (value 1), then on drive b (value 2): twice as tall.
  const int xa = FirstColumnWith(img, SeriesColor(0), 120);
  ASSERT_GT(xa, 0);
  const int ha = ColumnHeight(img, xa + 3, SeriesColor(0));
  const int xb = FirstColumnWith(img, SeriesColor(0), 400);
  ASSERT_GT(xb, 400);
  const int hb = ColumnHeight(img, xb + 3, SeriesColor(0));
  EXPECT_NEAR(hb, 2 * ha, 3) << ha << " " << hb;
  // The peer's bar on drive a is half of ours; it has no bar on drive b.
  const int xp = FirstColumnWith(img, SeriesColor(1), 120);
  ASSERT_GT(xp, xa);
  EXPECT_LT(xp, 400);
  EXPECT_NEAR(ColumnHeight(img, xp + 3, SeriesColor(1)), ha / 2.0, 3);
  EXPECT_EQ(FirstColumnWith(img, SeriesColor(1), 400), -1);
}

}  // namespace
}  // namespace cslam
