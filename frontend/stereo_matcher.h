#pragma once
// Stereo correspondence on rectified rows: a 1-D zero-mean NCC search along the left point's
// row over the whole disparity range (on the half-resolution images), sub-pixel refinement by
// 1-D NCC along x at full resolution, then checks that each reject what is wrong on its own:
// uniqueness, photometric score, row error (a vertical NCC fit), disparity range and the ORB
// descriptor distance between the left point and its right match.
//
// Uniqueness is checked twice: the coarse best must stand out from the rest of the search
// (max_ambiguity), and, with `unique_match`, no other disparity of the searched range may pass
// the photometric check too. A pattern that repeats along the row (a dashed line across the
// road, railings, a row of windows) has one acceptable match per period, and which one scores
// best depends on slant and exposure, not on which is true: on KITTI raw 0005 the wrong dash
// end scored 0.94 against the true one's 0.86. The wrong one puts the point at the depth of
// another period, consistently along its track (a tracked point's match is taken only near its
// last disparity), so the static world cannot explain the track and a dashed line became a
// "moving" object. The other periods are therefore looked for over the whole range for tracked
// points too.
#include <memory>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <span>
#include <string>
#include <vector>

namespace cslam {

class OptionsReader;
class TaskRunner;

/// Options of StereoMatcher.
struct StereoMatcherOptions {
  double min_disparity_px = 0.5;  ///< smallest accepted disparity (far points), px, > 0
  double max_disparity_px =
      160;                  ///< largest accepted disparity (near points), px; KITTI: Z ≈ 2.4 m
  int coarse_patch_px = 7;  ///< NCC window of the half-resolution search, px, odd, >= 3
  double max_ambiguity = 0.85;  ///< reject when (1 − best) > max_ambiguity · (1 − second-best
                                ///< peak NCC) in the coarse search; in (0, 1], 1 = off
  /// Reject a match when another disparity of the whole range passes min_ncc as well: a
  /// coarse peak (≥ 2 coarse px from the best, at least min_ncc) whose full-resolution NCC
  /// around it reaches min_ncc. With a prior disparity the whole range is still searched for
  /// such peaks (and for the ratio test's second best); only the best is taken near the
  /// prior. See the file comment.
  bool unique_match = true;
  int refine_radius_px = 3;     ///< full-resolution NCC search ± around the coarse match, px
  int patch_px = 11;            ///< full-resolution NCC window side, px, odd, >= 3
  double min_ncc = 0.75;        ///< photometric check on the refined match, in [-1, 1]
  double max_row_error_px = 1.0;  ///< |vertical offset| of the match (NCC parabola), px, > 0
  int max_hamming = 80;           ///< ORB distance left point ↔ right match, bits of 256
  /// With a prior disparity d (a tracked point's last one) the match is taken only within
  /// d ± (prior_margin_px + prior_margin_ratio · d): ~±45 % covers a car closing at 15 m/s at
  /// 3.5 m. Without unique_match only that window is searched at all.
  double prior_margin_px = 6;       ///< px, >= 2
  double prior_margin_ratio = 0.3;  ///< fraction of the prior disparity, >= 0
  /// Sub-pixel estimator after the integer NCC peak: "lk" = Gauss-Newton (ESM) alignment of
  /// the zero-mean, equal-norm windows along x with cubic interpolation (unbiased on exact
  /// shifts); "parabola" = vertex of the parabola through the three NCC scores around the
  /// peak (pulled towards whole pixels). The default stays "parabola": with "lk" the batch
  /// backend on KITTI raw 0005 went astray
  /// (docs/experiments/2026-12-01-real-drive-camera-subpixel-disparity-and-offset.md).
  std::string subpixel = "parabola";
  /// Added to every measured disparity, px (u_right is reported that much smaller): corrects
  /// a rectification whose right principal point is off by this much. 0 = trust the
  /// calibration. Finite.
  double disparity_offset_px = 0;

  void Check() const;
  void Load(OptionsReader& reader);
};

/// Why a left point found no stereo match (kOk when it did).
enum class StereoReject {
  kOk = 0,
  kOffImage,            ///< the windows (or the ORB patch) do not fit in the image
  kNoCandidate,         ///< no disparity of the range keeps the window inside the right image
  kAmbiguous,           ///< a second correlation peak nearly as good as the best, or
                        ///< another disparity that passes min_ncc too (unique_match)
  kNoPeak,              ///< full-resolution maximum on the edge of the refinement window
  kPhotometric,         ///< NCC below min_ncc
  kRowError,            ///< vertical offset above max_row_error_px
  kDisparityRange,      ///< refined disparity outside [min, max]
  kDescriptorDistance,  ///< ORB distance above max_hamming
};

/// A stereo correspondence of one left point.
struct StereoMatch {
  StereoReject status = StereoReject::kNoCandidate;
  float u_right = 0;       ///< refined right-image column, px (valid when status == kOk)
  float ncc = 0;           ///< NCC at the refined integer peak
  float row_error_px = 0;  ///< vertical offset of the right match (signed), px
  float curvature = 0;     ///< −d²NCC/du² at the peak (per px²): sharpness of the match
  int hamming = 0;         ///< ORB descriptor distance of the match
  bool ok() const { return status == StereoReject::kOk; }
};

/// Matches left points into the right image of a rectified pair. Holds the ORB extractors and
/// scratch buffers; not thread-safe (one instance per thread), but one call may spread its
/// points over a TaskRunner's threads.
class StereoMatcher {
 public:
  explicit StereoMatcher(const StereoMatcherOptions& options);
  ~StereoMatcher();
  StereoMatcher(StereoMatcher&&) noexcept;
  StereoMatcher& operator=(StereoMatcher&&) noexcept;

  /// One result per left point (same order). Images: the rectified CV_8UC1 pair.
  /// `prior_disparity` is empty or holds one value per point (px; <= 0 = no prior).
  /// `runner` (may be null): the points are matched in contiguous parts side by side, and the
  /// two images' descriptors computed side by side; the result does not depend on it.
  std::vector<StereoMatch> Match(const cv::Mat& left_grey, const cv::Mat& right_grey,
                                 std::span<const cv::Point2f> left_points,
                                 std::span<const float> prior_disparity = {},
                                 const TaskRunner* runner = nullptr);

  const StereoMatcherOptions& options() const { return options_; }

 private:
  struct Impl;
  StereoMatcherOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cslam
