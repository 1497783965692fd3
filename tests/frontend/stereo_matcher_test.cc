#include "frontend/stereo_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "tests/frontend/synthetic_images.h"

namespace cslam {
namespace {

const cv::Size kSize(640, 240);

/// Disparity of the synthetic plane at image row v: a ground-plane-like slant, 12.3..21.9 px.
double TrueDisparity(double v) { return 12.3 + 0.04 * v; }

struct Pair {
  cv::Mat left, right;
};
/// Left = texture; right(u, v) = left(u + d(v), v), so a left point (u, v) is at u − d(v).
Pair SlantedPlane(uint64_t seed, double row_shift_px = 0) {
  const cv::Mat texture = testing::RandomTexture(kSize, seed);
  Pair p;
  p.left = texture;
  p.right = testing::Warp(texture, kSize, [&](float u, float v) {
    return cv::Point2f(static_cast<float>(u + TrueDisparity(v - row_shift_px)),
                       static_cast<float>(v - row_shift_px));
  });
  return p;
}

TEST(StereoMatcher, MatchesHaveTheTrueDisparityOnASyntheticPlane) {
  const Pair pair = SlantedPlane(1);
  const std::vector<cv::Point2f> pts = testing::TestCorners(pair.left);
  ASSERT_GE(pts.size(), 300u);
  StereoMatcher matcher{StereoMatcherOptions{}};
  const std::vector<StereoMatch> matches = matcher.Match(pair.left, pair.right, pts);
  ASSERT_EQ(matches.size(), pts.size());
  int ok = 0;
  std::vector<double> errors;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!matches[i].ok()) continue;
    ++ok;
    const double d = pts[i].x - matches[i].u_right;
    errors.push_back(std::abs(d - TrueDisparity(pts[i].y)));
    EXPECT_LT(errors.back(), 0.3) << "at " << pts[i];
    EXPECT_LT(std::abs(matches[i].row_error_px), 0.3);
    EXPECT_GE(matches[i].ncc, 0.9);
  }
  // Points whose true match leaves the right image (u < d + border) cannot match.
  EXPECT_GE(ok, 0.9 * pts.size());
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.1);
}

TEST(StereoMatcher, RejectsDisparitiesOutsideTheRange) {
  const Pair pair = SlantedPlane(2);
  const std::vector<cv::Point2f> pts = testing::TestCorners(pair.left);
  StereoMatcherOptions near_only;
  near_only.min_disparity_px = 30;  // the plane is at 12..22 px
  near_only.max_disparity_px = 100;
  StereoMatcherOptions far_only;
  far_only.max_disparity_px = 8;
  for (const StereoMatcherOptions& o : {near_only, far_only}) {
    StereoMatcher matcher(o);
    const std::vector<StereoMatch> matches = matcher.Match(pair.left, pair.right, pts);
    for (size_t i = 0; i < pts.size(); ++i) {
      if (!matches[i].ok()) continue;
      // Anything accepted must be inside the range (a wrong match on random texture at most).
      const double d = pts[i].x - matches[i].u_right;
      EXPECT_GE(d, o.min_disparity_px);
      EXPECT_LE(d, o.max_disparity_px);
      EXPECT_GT(std::abs(d - TrueDisparity(pts[i].y)), 0.3);
    }
    const auto accepted =
        std::count_if(matches.begin(), matches.end(), [](const StereoMatch& m) { return m.ok(); });
    EXPECT_LT(accepted, 0.05 * pts.size());
  }
}

TEST(StereoMatcher, SearchesOnlyNearAPriorDisparity) {
  const Pair pair = SlantedPlane(5);
  const std::vector<cv::Point2f> pts = testing::TestCorners(pair.left);
  StereoMatcher matcher{StereoMatcherOptions{}};
  std::vector<float> near_truth, far_from_truth;
  for (const cv::Point2f& p : pts) {
    near_truth.push_back(static_cast<float>(TrueDisparity(p.y) + 3));
    far_from_truth.push_back(static_cast<float>(TrueDisparity(p.y) + 40));  // window 37..77 px away
  }
  const auto with_good_prior = matcher.Match(pair.left, pair.right, pts, near_truth);
  const auto with_bad_prior = matcher.Match(pair.left, pair.right, pts, far_from_truth);
  int good = 0, bad_right = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (with_good_prior[i].ok()) {
      ++good;
      EXPECT_NEAR(pts[i].x - with_good_prior[i].u_right, TrueDisparity(pts[i].y), 0.3);
    }
    bad_right += with_bad_prior[i].ok() &&
                 std::abs(pts[i].x - with_bad_prior[i].u_right - TrueDisparity(pts[i].y)) < 1;
  }
  EXPECT_GE(good, 0.9 * pts.size());
  EXPECT_EQ(bad_right, 0) << "the true disparity lies outside the prior's window";
}

TEST(StereoMatcher, RowCheckMeasuresAndRejectsAVerticalOffset) {
  // The right image is shifted down: the texture still matches, but not on the same row.
  StereoMatcher matcher{StereoMatcherOptions{}};
  for (const double shift : {0.4, 1.5}) {
    const Pair pair = SlantedPlane(3, shift);
    const std::vector<cv::Point2f> pts = testing::TestCorners(pair.left);
    const std::vector<StereoMatch> matches = matcher.Match(pair.left, pair.right, pts);
    int ok = 0, row = 0;
    std::vector<double> errors;
    for (const StereoMatch& m : matches) {
      ok += m.ok();
      row += m.status == StereoReject::kRowError;
      if (m.ok()) errors.push_back(std::abs(m.row_error_px - shift));
    }
    // The row estimate is a check, not a measurement: right on average, coarse per point.
    if (shift < StereoMatcherOptions{}.max_row_error_px) {
      std::sort(errors.begin(), errors.end());
      EXPECT_LT(errors[errors.size() / 2], 0.1) << "shift " << shift;
      EXPECT_LT(errors[errors.size() * 9 / 10], 0.3) << "shift " << shift;
    }
    if (shift < StereoMatcherOptions{}.max_row_error_px) {
      EXPECT_GE(ok, 0.8 * pts.size()) << "shift " << shift;
    } else {
      EXPECT_LT(ok, 0.05 * pts.size()) << "shift " << shift;
      // At 1.5 px the 11×11 NCC also drops below min_ncc for about half of the points.
      EXPECT_GT(row, 0.4 * pts.size()) << "the row check, not only the NCC one, must catch it";
    }
  }
}

TEST(StereoMatcher, RejectsWhenTheRightImageShowsDifferentTexture) {
  const Pair pair = SlantedPlane(4);
  const cv::Mat other = testing::RandomTexture(kSize, 99);
  const std::vector<cv::Point2f> pts = testing::TestCorners(pair.left);
  StereoMatcher matcher{StereoMatcherOptions{}};
  const std::vector<StereoMatch> matches = matcher.Match(pair.left, other, pts);
  const auto accepted =
      std::count_if(matches.begin(), matches.end(), [](const StereoMatch& m) { return m.ok(); });
  EXPECT_LT(accepted, 0.02 * pts.size());
}

TEST(StereoMatcherOptions, CheckNamesTheBrokenField) {
  StereoMatcherOptions o;
  EXPECT_NO_THROW(o.Check());
  o.max_disparity_px = o.min_disparity_px;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_disparity_px"), std::string::npos);
  }
  o = StereoMatcherOptions{};
  o.patch_px = 10;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
