#pragma once
// Procedural grey textures for rendered synthetic scenes. A "dead leaves" pattern (random
// discs and rotated rectangles painted over each other, sizes from a power law) has edges and
// corners at every scale, so a FAST/ORB detector and a KLT tracker find structure whether the
// surface is seen from 3 m or from 40 m, and two different seeds look nothing alike (no
// accidental matches between surfaces). The pattern tiles seamlessly (shapes wrap around the
// borders), so it can be repeated over a large surface with GL_REPEAT.
#include <cstdint>
#include <opencv2/core/mat.hpp>

namespace cslam {

/// Parameters of a dead-leaves texture.
struct ProceduralTextureOptions {
  int size_px = 512;          ///< square side, texels, power of two in [16, 4096]
  double min_radius_px = 1.5; ///< smallest shape (radius or half side), texels, > 0
  double max_radius_px = 60;  ///< largest shape, texels, >= min_radius_px
  double coverage = 12.0;     ///< painted area / texture area (>= ~5 leaves no gaps), > 0
  int min_grey = 25, max_grey = 230;  ///< shape intensities, in [0, 255], min <= max

  /// Throws ConfigError naming the field and the rule.
  void Check() const;
};

/// The CV_8UC1 size_px × size_px texture of `seed` (same seed and options = same texels, on
/// every platform: the random stream and the shapes are drawn by this code, not by libc).
cv::Mat MakeDeadLeavesTexture(uint64_t seed, const ProceduralTextureOptions& options = {});

}  // namespace cslam
