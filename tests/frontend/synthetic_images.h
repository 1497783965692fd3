#pragma once
// Synthetic grey images with a known answer for frontend tests: smooth random texture warped
// with cv::remap, so every pixel's true stereo disparity and frame-to-frame motion are known.
#include <cmath>
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

/// A band-limited texture known in closed form: a sum of random plane waves (periods 3–40 px,
/// random orientation and phase) sampled at (u + shift_x, v + shift_y) for every pixel (u, v).
/// Shifted copies are exact to float precision at any sub-pixel shift, with no interpolation
/// in between: the ground truth for sub-pixel estimators. Deterministic in `seed`; the same
/// seed gives the same continuous texture for every shift.
inline cv::Mat WaveTexture(cv::Size size, uint64_t seed, double shift_x = 0, double shift_y = 0,
                           int waves = 120) {
  cv::RNG rng(seed);
  cv::Mat acc = cv::Mat::zeros(size, CV_64F);
  double power = 0;
  std::vector<double> cu(size.width), su(size.width), cv_(size.height), sv(size.height);
  for (int k = 0; k < waves; ++k) {
    const double period = 3.0 * std::pow(40.0 / 3.0, rng.uniform(0.0, 1.0));
    const double angle = rng.uniform(0.0, CV_PI);
    const double phase = rng.uniform(0.0, 2 * CV_PI);
    // Longer waves carry more amplitude, as in natural images (~1/f).
    const double amp = period;
    power += amp * amp / 2;
    const double a = 2 * CV_PI / period * std::cos(angle), b = 2 * CV_PI / period * std::sin(angle);
    // sin(a x + b y + φ) = sin(a x + φ) cos(b y) + cos(a x + φ) sin(b y): separable tables.
    for (int u = 0; u < size.width; ++u) {
      su[u] = std::sin(a * (u + shift_x) + phase);
      cu[u] = std::cos(a * (u + shift_x) + phase);
    }
    for (int v = 0; v < size.height; ++v) {
      cv_[v] = std::cos(b * (v + shift_y));
      sv[v] = std::sin(b * (v + shift_y));
    }
    for (int v = 0; v < size.height; ++v) {
      double* row = acc.ptr<double>(v);
      for (int u = 0; u < size.width; ++u) row[u] += amp * (su[u] * cv_[v] + cu[u] * sv[v]);
    }
  }
  // A grey mapping fixed by the amplitudes (not per-image normalisation), so shifted copies
  // share it exactly: 35 grey levels per standard deviation around 128.
  cv::Mat out;
  acc.convertTo(out, CV_8U, 35.0 / std::sqrt(power), 128.0);
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
