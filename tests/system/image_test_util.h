#pragma once
// Pixel checks for rendered images (8-bit BGR).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <string>

#include "system/io/image_io.h"

namespace cslam::testing {

/// Largest channel difference between two BGR pixels.
inline int ColourDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
  return d;
}

/// True when a pixel within `radius` of `px` has colour `bgr` up to `tolerance` per channel.
inline ::testing::AssertionResult ColourNear(const cv::Mat& image, const Eigen::Vector2d& px,
                                             const cv::Vec3b& bgr, int radius, int tolerance) {
  const int u0 = static_cast<int>(std::lround(px.x())), v0 = static_cast<int>(std::lround(px.y()));
  int best = 256;
  cv::Vec3b best_pixel;
  for (int v = v0 - radius; v <= v0 + radius; ++v)
    for (int u = u0 - radius; u <= u0 + radius; ++u) {
      if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
      const int d = ColourDistance(image.at<cv::Vec3b>(v, u), bgr);
      if (d < best) {
        best = d;
        best_pixel = image.at<cv::Vec3b>(v, u);
      }
    }
  if (best <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "no pixel within " << radius << " px of (" << px.x() << ", " << px.y()
         << ") has BGR " << cv::Vec3i(bgr) << " (closest " << cv::Vec3i(best_pixel)
         << ", off by " << best << ")";
}

/// Fraction of 1-px steps along the pixel segment pa-pb where a pixel within 1 px has colour
/// `bgr` up to `tolerance` (how much of a drawn line shows).
inline double SegmentCoverage(const cv::Mat& image, const Eigen::Vector2d& pa,
                              const Eigen::Vector2d& pb, const cv::Vec3b& bgr, int tolerance) {
  const int steps = std::max(1, static_cast<int>((pb - pa).norm()));
  int hits = 0;
  for (int i = 0; i <= steps; ++i)
    hits += static_cast<bool>(
        ColourNear(image, pa + (pb - pa) * (double(i) / steps), bgr, 1, tolerance));
  return double(hits) / (steps + 1);
}

/// Number of pixels of colour `bgr` up to `tolerance`.
inline int CountColour(const cv::Mat& image, const cv::Vec3b& bgr, int tolerance) {
  int n = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) n += ColourDistance(image.at<cv::Vec3b>(v, u), bgr) <= tolerance;
  return n;
}

/// Saves `image` under $CSLAM_TEST_IMAGE_DIR (when set) for a human to look at.
inline void MaybeSave(const cv::Mat& image, const std::string& name) {
  if (const char* dir = std::getenv("CSLAM_TEST_IMAGE_DIR")) WritePng(image, std::string(dir) + "/" + name);
}

}  // namespace cslam::testing
