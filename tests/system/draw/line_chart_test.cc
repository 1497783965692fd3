#include "system/draw/line_chart.h"

#include <gtest/gtest.h>

namespace cslam {
namespace {

int CountColor(const cv::Mat& img, const cv::Scalar& bgr, int tol = 30) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - bgr[0]) <= tol && std::abs(p[1] - bgr[1]) <= tol &&
          std::abs(p[2] - bgr[2]) <= tol)
        ++n;
    }
  return n;
}

TEST(LineChart, DrawsEverySeriesInItsColourAndNothingElseInColour) {
  LineChart c;
  c.title = "t";
  c.series = {{"a", {0, 1, 2}, {0, 1, 0}, SeriesColor(0)}, {"b", {0, 1, 2}, {1, 0, 1}, SeriesColor(1)}};
  const cv::Mat img = RenderLineChart(c, 600, 400);
  ASSERT_EQ(img.size(), cv::Size(600, 400));
  EXPECT_GT(CountColor(img, SeriesColor(0)), 200);
  EXPECT_GT(CountColor(img, SeriesColor(1)), 200);
  EXPECT_LT(CountColor(img, SeriesColor(2)), 5);
}

TEST(LineChart, PlacesAPointWhereTheAxesSay) {
  // One marker at (1, 0.5) on axes fixed to [0, 1]: the plot area is x 90..570, y 60..330.
  LineChart c;
  c.series = {{"p", {0, 1}, {0.5, 0.5}, cv::Scalar(0, 0, 255)}};
  c.y_min = 0;
  c.y_max = 1;
  const cv::Mat img = RenderLineChart(c, 600, 400);
  const cv::Vec3b mid = img.at<cv::Vec3b>(60 + 135, 90 + 240);  // halfway along the line
  EXPECT_GT(mid[2], 200);
  EXPECT_LT(mid[1], 80);
  const cv::Vec3b off = img.at<cv::Vec3b>(60 + 30, 90 + 240);  // y = 0.89: white
  EXPECT_GT(off[1], 200);
}

}  // namespace
}  // namespace cslam
