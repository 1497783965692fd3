#pragma once
// Does the calibration rectify these images? Measured from stereo matches: after a correct
// rectification a point sits on the same row in both images, so the vertical offsets of
// matched features are ~0 px (docs/own_rig.md, `cslam calib check`).
#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

#include "system/datasets/stereo_source.h"

namespace cslam {

/// Vertical offsets |v_left - v_right| of stereo feature matches, pixels.
struct VerticalOffsets {
  int matches = 0;
  double median = 0, p90 = 0;
};

/// Follows corners of the left image into the right one (pyramidal Lucas-Kanade with a
/// forward-backward check of 0.5 px, right column <= left column + 1) and summarises the rows'
/// differences.
VerticalOffsets MeasureVerticalOffsets(const cv::Mat& left, const cv::Mat& right);

/// The outcome of checking a rig on its images.
struct RigImageCheck {
  VerticalOffsets rectified;  ///< over the checked pairs, after rectification
  VerticalOffsets raw;        ///< the same pairs as recorded (matches 0 when not measured)
  bool ok = true;
  bool measured = true;       ///< false: too few matches to tell (then !ok too)
  std::string problem;        ///< what is wrong and the likely mistake, when !ok
};

/// The largest median vertical offset a rig passes with, pixels.
inline constexpr double kMaxMedianVerticalOffsetPx = 1.0;

/// Measures `frames` of `source` (a RigStereoSource also as recorded). Fails when the
/// rectified median offset exceeds kMaxMedianVerticalOffsetPx, with the hint "are these images
/// already rectified?" when the rig has distortion coefficients and the raw images are better
/// aligned than the rectified ones, or when too few features match to tell.
RigImageCheck CheckRigOnImages(const StereoSource& source, const std::vector<int>& frames);

/// The rectified pair side by side with a horizontal line every `line_every` pixels (BGR).
cv::Mat SideBySideWithLines(const cv::Mat& left, const cv::Mat& right, int line_every = 24);

}  // namespace cslam
