#pragma once
// Synthetic grey images with a known answer for frontend tests: smooth random texture warped
// with cv::remap, so every pixel's true stereo disparity and frame-to-frame motion are known.
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "frontend/grid_detector.h"

namespace cslam::testing {

/// Random texture, Gaussian-blurred (σ = blur_px) so that bilinear/bicubic resampling is
/// accurate, stretched to use most of [0, 255]. Deterministic in `seed`.
inline cv::Mat RandomTexture(cv::Size size, uint64_t seed, double blur_px = 1.5) {
  cv::Mat noise(size, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), blur_px);
  cv::Mat out;
  cv::normalize(noise, out, 10, 245, cv::NORM_MINMAX, CV_8U);
  return out;
}

/// out(u, v) = src(source_x(u, v), source_y(u, v)) with bicubic interpolation.
inline cv::Mat Warp(const cv::Mat& src, cv::Size size,
                    const std::function<cv::Point2f(float u, float v)>& source) {
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) {
      const cv::Point2f s = source(static_cast<float>(u), static_cast<float>(v));
      map_x.at<float>(v, u) = s.x;
      map_y.at<float>(v, u) = s.y;
    }
  cv::Mat out;
  cv::remap(src, out, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  return out;
}

/// Grid FAST corners of a test image (400 on a 16×6 grid): the points the tests track and match.
inline std::vector<cv::Point2f> TestCorners(const cv::Mat& image) {
  GridDetectorOptions o;
  o.target_count = 400;
  o.grid_cols = 16;
  o.grid_rows = 6;
  std::vector<cv::Point2f> pts;
  for (const DetectedKeypoint& k : GridDetector(o).Detect(image, {})) pts.push_back(k.pt);
  return pts;
}

}  // namespace cslam::testing
