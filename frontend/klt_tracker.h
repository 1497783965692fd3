#pragma once
// Temporal tracking of keypoints between consecutive left images: pyramidal Lucas-Kanade
// with a forward-backward consistency check and a photometric (NCC) check. No check against
// the camera's own motion: independently moving points are what the backend clusters.
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <span>
#include <vector>

namespace cslam {

class OptionsReader;

/// Options of KltTracker.
struct KltTrackerOptions {
  int window_px = 11;            ///< Lucas-Kanade window side, px, odd, >= 5 (cost ∝ area)
  int max_level = 3;             ///< coarsest pyramid level (0 = no pyramid), in [0, 8]
  int max_iterations = 20;       ///< LK iterations per level, > 0
  double epsilon_px = 0.03;      ///< LK stops when the update is below this, px, > 0
  double max_fb_error_px = 0.5;  ///< forward-backward round-trip error allowed, px, > 0
  int ncc_patch_px = 11;         ///< window of the photometric check, px, odd, >= 3
  double min_ncc = 0.7;          ///< previous vs current patch NCC; -1 disables the check
  double border_px = 8;          ///< tracked points must stay this far inside the image, px

  void Check() const;
  void Load(OptionsReader& reader);
};

/// Why a track was dropped (kOk when it continues).
enum class TrackReject {
  kOk = 0,
  kLost,             ///< LK did not converge (forward or backward)
  kOutOfImage,       ///< left the image (minus border)
  kForwardBackward,  ///< round trip returned farther than max_fb_error_px
  kPhotometric,      ///< NCC below min_ncc
};

/// Result for one tracked point.
struct TrackResult {
  TrackReject status = TrackReject::kLost;
  cv::Point2f pt;         ///< position in the current image, px
  float fb_error_px = 0;  ///< forward-backward round-trip distance, px
  float ncc = 0;          ///< previous vs current patch NCC
  bool ok() const { return status == TrackReject::kOk; }
};

/// An image pyramid with LK derivatives, built once per frame and used both as "current" (for
/// the forward pass) and, a frame later, as "previous".
struct KltPyramid {
  cv::Mat image;                ///< level-0 grey image (CV_8UC1), a copy owned by the pyramid
  std::vector<cv::Mat> levels;  ///< cv::buildOpticalFlowPyramid output
};

/// Pyramidal KLT tracker. Stateless apart from its options; thread-compatible.
class KltTracker {
 public:
  explicit KltTracker(const KltTrackerOptions& options);

  KltPyramid BuildPyramid(const cv::Mat& grey) const;
  /// Tracks `prev_points` from `prev` into `cur`. `predicted` (same size, or empty) are
  /// initial guesses in `cur`, e.g. the point's previous image motion added on.
  std::vector<TrackResult> Track(const KltPyramid& prev, const KltPyramid& cur,
                                 std::span<const cv::Point2f> prev_points,
                                 std::span<const cv::Point2f> predicted = {}) const;

  const KltTrackerOptions& options() const { return options_; }

 private:
  KltTrackerOptions options_;
};

}  // namespace cslam
