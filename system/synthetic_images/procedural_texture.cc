#include "system/synthetic_images/procedural_texture.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/options_reader.h"

namespace cslam {

void ProceduralTextureOptions::Check() const {
  CheckOption(size_px >= 16 && size_px <= 4096 && (size_px & (size_px - 1)) == 0, "size_px",
              "must be a power of two in [16, 4096]", size_px);
  CheckOption(std::isfinite(min_radius_px) && min_radius_px > 0, "min_radius_px", "must be > 0",
              min_radius_px);
  CheckOption(std::isfinite(max_radius_px) && max_radius_px >= min_radius_px &&
                  max_radius_px <= size_px / 2,
              "max_radius_px", "must be in [min_radius_px, size_px / 2]", max_radius_px);
  CheckOption(std::isfinite(coverage) && coverage > 0 && coverage <= 100, "coverage",
              "must be in (0, 100]", coverage);
  CheckOption(min_grey >= 0 && min_grey <= max_grey, "min_grey", "must be in [0, max_grey]", min_grey);
  CheckOption(max_grey <= 255, "max_grey", "must be <= 255", max_grey);
}

namespace {

/// Uniform doubles from the standard-fixed mt19937_64 output (std distributions differ
/// between standard libraries).
class Stream {
 public:
  explicit Stream(uint64_t seed) {
    uint64_t z = seed * 0x9E3779B97F4A7C15ULL + 0x2545F4914F6CDD1DULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    engine_.seed(z ^ (z >> 31));
  }
  double Uniform(double a = 0.0, double b = 1.0) {
    return a + (b - a) * (static_cast<double>(engine_() >> 11) * 0x1.0p-53);
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace

cv::Mat MakeDeadLeavesTexture(uint64_t seed, const ProceduralTextureOptions& o) {
  o.Check();
  const int n = o.size_px;
  std::vector<float> img(static_cast<size_t>(n) * n, 0.5f * (o.min_grey + o.max_grey));
  Stream rng(seed);
  // Radii with density ∝ r^-3 between the bounds: every octave of sizes covers the same area,
  // so the pattern looks alike at every viewing distance (scale invariance).
  const double a = std::pow(o.min_radius_px, -2.0), b = std::pow(o.max_radius_px, -2.0);
  const double target_area = o.coverage * n * n;
  double painted = 0.0;
  while (painted < target_area) {
    const double r = std::pow(a - rng.Uniform() * (a - b), -0.5);
    const double cx = rng.Uniform(0, n), cy = rng.Uniform(0, n);
    const float grey = static_cast<float>(rng.Uniform(o.min_grey, o.max_grey));
    const bool disc = rng.Uniform() < 0.5;
    // Rectangles: half sides r and r·aspect, rotated by theta (corners for FAST and ORB).
    const double aspect = rng.Uniform(0.3, 1.0), theta = rng.Uniform(0, std::numbers::pi);
    const double c = std::cos(theta), s = std::sin(theta);
    const double hx = r, hy = r * aspect;
    painted += disc ? std::numbers::pi * r * r : 4.0 * hx * hy;
    const double reach = r + 1.0;
    const int x0 = static_cast<int>(std::floor(cx - reach)), x1 = static_cast<int>(std::ceil(cx + reach));
    const int y0 = static_cast<int>(std::floor(cy - reach)), y1 = static_cast<int>(std::ceil(cy + reach));
    for (int y = y0; y <= y1; ++y) {
      const int wy = ((y % n) + n) % n;  // wrap: the texture tiles seamlessly
      for (int x = x0; x <= x1; ++x) {
        const double dx = x - cx, dy = y - cy;
        // Signed distance to the shape's boundary (negative inside), in texels.
        double d;
        if (disc) {
          d = std::sqrt(dx * dx + dy * dy) - r;
        } else {
          const double u = c * dx + s * dy, v = -s * dx + c * dy;
          d = std::max(std::abs(u) - hx, std::abs(v) - hy);
        }
        // One texel of anti-aliasing: coverage of the pixel by the shape.
        const double alpha = std::clamp(0.5 - d, 0.0, 1.0);
        if (alpha <= 0.0) continue;
        const int wx = ((x % n) + n) % n;
        float& p = img[static_cast<size_t>(wy) * n + wx];
        p = static_cast<float>(p * (1.0 - alpha) + grey * alpha);
      }
    }
  }
  cv::Mat out(n, n, CV_8UC1);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      out.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(std::clamp(img[static_cast<size_t>(y) * n + x], 0.0f, 255.0f)));
  return out;
}

}  // namespace cslam
