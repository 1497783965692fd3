#include "frontend/image_patch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "tests/frontend/synthetic_images.h"

namespace cslam {
namespace {

/// Bilinear value of an 8-bit image at (x, y), in double: the ground truth of SampleStrip.
double Bilinear(const cv::Mat& grey, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int r, int c) { return static_cast<double>(grey.at<uint8_t>(r, c)); };
  return (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x0 + 1)) +
         fy * ((1 - fx) * at(y0 + 1, x0) + fx * at(y0 + 1, x0 + 1));
}

TEST(SampleStrip, NarrowAndWideStripsAreTheBilinearImageBitForBit) {
  const cv::Mat grey = testing::RandomTexture(cv::Size(320, 120), 7);
  cv::RNG rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const float x = rng.uniform(1.f, 150.f), y = rng.uniform(1.f, 90.f);
    std::vector<float> narrow, wide;
    // 17 columns take the row-buffered path, 150 the plain loop: the same values.
    ASSERT_TRUE(SampleStrip(grey, x, y, 17, 11, &narrow));
    ASSERT_TRUE(SampleStrip(grey, x, y, 150, 11, &wide));
    for (int r = 0; r < 11; ++r)
      for (int c = 0; c < 17; ++c) {
        EXPECT_EQ(narrow[r * 17 + c], wide[r * 150 + c]) << r << "," << c;
        EXPECT_NEAR(narrow[r * 17 + c], Bilinear(grey, x + c, y + r), 1e-3);
      }
  }
  std::vector<float> strip;
  EXPECT_FALSE(SampleStrip(grey, 310.5f, 10.f, 17, 11, &strip));  // right edge
  EXPECT_FALSE(SampleStrip(grey, 10.f, 109.5f, 17, 11, &strip));  // bottom edge
  EXPECT_FALSE(SampleStrip(grey, -0.5f, 10.f, 17, 11, &strip));
}

TEST(NccAlongXY, EqualNccAtForEveryShiftAndPeakAtTheTrueShift) {
  const cv::Mat grey = testing::RandomTexture(cv::Size(200, 100), 11);
  cv::RNG rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const float x = rng.uniform(30.f, 150.f), y = rng.uniform(20.f, 70.f);
    const int shift = rng.uniform(1, 6);  // true offset of the template inside the strips
    ImagePatch patch;
    ASSERT_TRUE(SamplePatch(grey, x, y, 11, &patch));
    const NccTemplate templ = PrepareNcc(patch);
    ASSERT_GT(templ.norm, 0);
    NccTemplate reused;
    reused.zero_mean.assign(500, 1.f);  // stale, larger storage must not leak into the result
    PrepareNcc(patch, &reused);
    EXPECT_EQ(reused.zero_mean, templ.zero_mean);
    EXPECT_EQ(reused.norm, templ.norm);

    // Along x: a strip 11 + 6 wide whose window at `shift` is the template's.
    std::vector<float> row_strip, col_strip;
    ASSERT_TRUE(SampleStrip(grey, x - 5 - shift, y - 5, 17, 11, &row_strip));
    double along_x[kMaxNccShifts];
    NccAlongX(templ, row_strip, 17, 7, along_x);
    int best = 0;
    for (int s = 0; s < 7; ++s) {
      EXPECT_NEAR(along_x[s], NccAt(templ, row_strip, 17, s, 0), 1e-6) << s;
      if (along_x[s] > along_x[best]) best = s;
    }
    EXPECT_EQ(best, shift);
    // The window sums are float (as in NccAt): ~1e-5 of cancellation in the variance.
    EXPECT_NEAR(along_x[shift], 1.0, 1e-4);

    // Along y: a column 11 wide, 11 + 4 high.
    const int vshift = shift % 5;
    ASSERT_TRUE(SampleStrip(grey, x - 5, y - 5 - vshift, 11, 15, &col_strip));
    double along_y[kMaxNccShifts];
    NccAlongY(templ, col_strip, 11, 5, along_y);
    best = 0;
    for (int s = 0; s < 5; ++s) {
      EXPECT_NEAR(along_y[s], NccAt(templ, col_strip, 11, 0, s), 1e-6) << s;
      if (along_y[s] > along_y[best]) best = s;
    }
    EXPECT_EQ(best, vshift);
  }
}

TEST(NccAlongXY, AFlatTemplateScoresZeroEverywhere) {
  ImagePatch flat{11, std::vector<float>(121, 100.f)};
  const NccTemplate templ = PrepareNcc(flat);
  EXPECT_EQ(templ.norm, 0);
  const cv::Mat grey = testing::RandomTexture(cv::Size(100, 60), 2);
  std::vector<float> strip;
  ASSERT_TRUE(SampleStrip(grey, 10, 10, 17, 11, &strip));
  double out[kMaxNccShifts];
  NccAlongX(templ, strip, 17, 7, out);
  for (int s = 0; s < 7; ++s) EXPECT_EQ(out[s], 0.0);
}

}  // namespace
}  // namespace cslam
