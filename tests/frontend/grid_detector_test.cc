#include "frontend/grid_detector.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/options_reader.h"
#include "tests/frontend/synthetic_images.h"

namespace cslam {
namespace {

const cv::Size kSize(1242, 375);

GridDetectorOptions Defaults() { return GridDetectorOptions{}; }

TEST(GridDetector, SpreadsTheTargetEvenlyOverUniformTexture) {
  const cv::Mat image = testing::RandomTexture(kSize, 11);
  const GridDetector detector(Defaults());
  const std::vector<DetectedKeypoint> kps = detector.Detect(image, {});
  EXPECT_EQ(static_cast<int>(kps.size()), Defaults().target_count);
  std::vector<int> per_cell(detector.num_cells(), 0);
  for (const DetectedKeypoint& k : kps) {
    const int cell = detector.CellOf(k.pt, kSize);
    ASSERT_GE(cell, 0);
    ++per_cell[cell];
    EXPECT_GE(k.pt.x, Defaults().border_px);
    EXPECT_LE(k.pt.x, kSize.width - 1 - Defaults().border_px);
  }
  // Interior cells (not clipped by the border) each get their quota of ceil(1500 / 192) = 8.
  const int quota = (Defaults().target_count + detector.num_cells() - 1) / detector.num_cells();
  for (int r = 1; r < Defaults().grid_rows - 1; ++r)
    for (int c = 1; c < Defaults().grid_cols - 1; ++c)
      EXPECT_GE(per_cell[r * Defaults().grid_cols + c], quota) << "cell " << r << "," << c;
}

TEST(GridDetector, KeepsMinimumSpacingFromExistingAndNewPoints) {
  const cv::Mat image = testing::RandomTexture(kSize, 12);
  GridDetectorOptions o = Defaults();
  const GridDetector detector(o);
  std::vector<cv::Point2f> existing;
  for (int x = 100; x < 1100; x += 50) existing.emplace_back(static_cast<float>(x), 180.f);
  const std::vector<DetectedKeypoint> kps = detector.Detect(image, existing);
  EXPECT_EQ(kps.size() + existing.size(), static_cast<size_t>(o.target_count));
  std::vector<cv::Point2f> all = existing;
  for (const DetectedKeypoint& k : kps) all.push_back(k.pt);
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size(); ++j)
      ASSERT_GE(std::hypot(all[i].x - all[j].x, all[i].y - all[j].y), o.min_distance_px - 1e-3);
}

TEST(GridDetector, RedetectsOnlyInCellsTheTracksLeftEmpty) {
  const cv::Mat image = testing::RandomTexture(kSize, 13);
  const GridDetector detector(Defaults());
  const std::vector<DetectedKeypoint> first = detector.Detect(image, {});
  // Keep the tracks of the left half only: new points must go to the right half.
  std::vector<cv::Point2f> live;
  for (const DetectedKeypoint& k : first)
    if (k.pt.x < kSize.width / 2) live.push_back(k.pt);
  const std::vector<DetectedKeypoint> again = detector.Detect(image, live);
  ASSERT_FALSE(again.empty());
  int right = 0;
  for (const DetectedKeypoint& k : again)
    right += k.pt.x >= kSize.width / 2 - Defaults().min_distance_px;
  EXPECT_EQ(right, static_cast<int>(again.size()));
}

TEST(GridDetectorOptions, LoadReadsEveryFieldAndCheckNamesTheBrokenOne) {
  OptionsReader reader = OptionsReader::FromString(
      "target_count: 800\ngrid_cols: 12\ngrid_rows: 4\nfast_threshold: 30\n"
      "min_distance_px: 12.5\nborder_px: 24\n",
      "test");
  GridDetectorOptions o;
  EXPECT_NO_THROW(reader.LoadInto(&o));
  EXPECT_EQ(o.target_count, 800);
  EXPECT_EQ(o.grid_cols, 12);
  EXPECT_EQ(o.grid_rows, 4);
  EXPECT_EQ(o.fast_threshold, 30);
  EXPECT_DOUBLE_EQ(o.min_distance_px, 12.5);
  EXPECT_EQ(o.border_px, 24);
  o.border_px = 3;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("border_px"), std::string::npos);
  }
}

}  // namespace
}  // namespace cslam
