#include "system/runtime/resource_log.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

TEST(ResourceLog, FrameRateIsFramesOverTimeBetweenSamples) {
  const std::vector<ResourceSample> s = {{10, 1.0, 100}, {20, 2.0, 101}, {40, 3.0, 102}};
  const std::vector<double> fps = FramesPerSecond(s);
  ASSERT_EQ(fps.size(), 2u);
  EXPECT_DOUBLE_EQ(fps[0], 10.0);
  EXPECT_DOUBLE_EQ(fps[1], 20.0);
}

TEST(ResourceLog, WritesTheCsv) {
  testing::TempDir tmp("resource_log");
  std::vector<ResourceSample> s;
  for (int k = 1; k <= 300; ++k) s.push_back({10 * k, 0.5 * k, 200.0 + 0.01 * k});
  WriteResourceLog(s, tmp.path().string());
  std::ifstream csv(tmp.path() / "resources.csv");
  std::string header, first, second;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_EQ(header, "frame,elapsed_s,rss_mb,fps");
  EXPECT_EQ(first, "10,0.500,200.0,");
  EXPECT_EQ(second, "20,1.000,200.0,20.00");
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "render"));  // the chart is the run's
}

TEST(ResourceLog, ReadsBackWhatItWroteAndNamesABadLine) {
  testing::TempDir tmp("resource_log_read");
  const std::vector<ResourceSample> s = {{10, 1.5, 100.5}, {20, 2.25, 101.0}};
  WriteResourceLog(s, tmp.path().string());
  const std::vector<ResourceSample> back = ReadResourceLog((tmp.path() / "resources.csv").string());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].frame, 20);
  EXPECT_DOUBLE_EQ(back[1].elapsed_s, 2.25);
  EXPECT_DOUBLE_EQ(back[0].rss_mb, 100.5);
  { std::ofstream(tmp.path() / "resources.csv", std::ios::app) << "30,abc,1,\n"; }
  try {
    ReadResourceLog((tmp.path() / "resources.csv").string());
    FAIL() << "a malformed line was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":4"), std::string::npos) << e.what();
  }
}

TEST(ResourceLog, FewerThanTwoSamplesWriteNothing) {
  testing::TempDir tmp("resource_log_one");
  WriteResourceLog({{10, 1.0, 100}}, tmp.path().string());
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "resources.csv"));
}

}  // namespace
}  // namespace cslam
