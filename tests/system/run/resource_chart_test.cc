#include "system/run/resource_chart.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

TEST(ResourceChart, DrawsMemoryAndFrameRateIntoRender) {
  testing::TempDir tmp("resource_chart");
  std::vector<ResourceSample> s;
  for (int k = 1; k <= 300; ++k) s.push_back({10 * k, 0.5 * k, 200.0 + 0.01 * k});
  WriteResourceChart(s, tmp.path().string());
  const cv::Mat chart = cv::imread((tmp.path() / "render" / "resources.png").string());
  ASSERT_FALSE(chart.empty());
  cv::Mat grey;
  cv::extractChannel(chart, grey, 0);
  EXPECT_GT(cv::countNonZero(grey < 200), 1000);  // axes, text and the two lines
}

TEST(ResourceChart, FewerThanTwoSamplesDrawNothing) {
  testing::TempDir tmp("resource_chart_one");
  WriteResourceChart({{10, 1.0, 100}}, tmp.path().string());
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "render"));
}

}  // namespace
}  // namespace cslam
