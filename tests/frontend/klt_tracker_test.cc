#include "frontend/klt_tracker.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/frontend/synthetic_images.h"

namespace cslam {
namespace {

const cv::Size kSize(640, 240);

const cv::Point2f kShift(3.4f, -1.7f);

TEST(KltTracker, FollowsAKnownImageMotion) {
  const cv::Mat a = testing::RandomTexture(kSize, 7);
  // b(u, v) = a(u − s): every point moves by +s.
  const cv::Mat b =
      testing::Warp(a, kSize, [](float u, float v) { return cv::Point2f(u, v) - kShift; });
  const std::vector<cv::Point2f> pts = testing::TestCorners(a);
  ASSERT_GE(pts.size(), 300u);
  const KltTracker tracker{KltTrackerOptions{}};
  const auto results = tracker.Track(tracker.BuildPyramid(a), tracker.BuildPyramid(b), pts);
  int ok = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!results[i].ok()) continue;
    ++ok;
    const cv::Point2f err = results[i].pt - (pts[i] + kShift);
    EXPECT_LT(std::hypot(err.x, err.y), 0.3) << "at " << pts[i];
    EXPECT_LE(results[i].fb_error_px, KltTrackerOptions{}.max_fb_error_px);
    EXPECT_GT(results[i].ncc, 0.9);
  }
  EXPECT_GE(ok, 0.95 * pts.size());
}

TEST(KltTracker, ForwardBackwardCheckRejectsAPatchReplacedByOtherTexture) {
  const cv::Mat a = testing::RandomTexture(kSize, 8);
  cv::Mat b = testing::Warp(a, kSize, [](float u, float v) { return cv::Point2f(u, v) - kShift; });
  const cv::Rect replaced(200, 60, 160, 120);
  testing::RandomTexture(kSize, 1234)(replaced).copyTo(b(replaced));

  KltTrackerOptions o;
  o.min_ncc = -1;  // the forward-backward check alone must catch it
  const KltTracker tracker(o);
  const std::vector<cv::Point2f> pts = testing::TestCorners(a);
  const auto results = tracker.Track(tracker.BuildPyramid(a), tracker.BuildPyramid(b), pts);
  // Points well inside the replaced region (their window sees only the new texture) versus
  // points well outside it.
  cv::Rect inner = replaced;
  inner -= cv::Size(2 * o.window_px, 2 * o.window_px);
  inner += cv::Point(o.window_px, o.window_px);
  cv::Rect outer = replaced;
  outer += cv::Size(2 * o.window_px, 2 * o.window_px);
  outer -= cv::Point(o.window_px, o.window_px);
  int inside = 0, inside_kept = 0, outside = 0, outside_kept = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const cv::Point p(static_cast<int>(pts[i].x + kShift.x), static_cast<int>(pts[i].y + kShift.y));
    if (inner.contains(p)) {
      ++inside;
      inside_kept += results[i].ok();
    } else if (!outer.contains(p)) {
      ++outside;
      outside_kept += results[i].ok();
    }
  }
  ASSERT_GE(inside, 20);
  EXPECT_LE(inside_kept, 0.05 * inside) << inside_kept << " of " << inside << " kept";
  EXPECT_GE(outside_kept, 0.95 * outside);
}

}  // namespace
}  // namespace cslam
