#pragma once
// FAST corners with grid bucketing: an even spread of keypoints over the image, topping up
// only the cells that the live tracks no longer fill (re-detection in emptied cells).
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <span>
#include <vector>

namespace cslam {

class OptionsReader;

/// Options of GridDetector.
struct GridDetectorOptions {
  int target_count = 1500;     ///< keypoints wanted per image (live tracks + new ones), > 0
  int grid_cols = 24;          ///< grid cells across the image, > 0
  int grid_rows = 8;           ///< grid cells down the image, > 0
  int fast_threshold = 12;     ///< FAST intensity threshold, grey levels, in [1, 255]
  double min_distance_px = 8;  ///< minimum spacing between keypoints (new and live), px, > 0
  int border_px = 20;  ///< keypoints keep this far from the image edge (ORB patch), px, >= 16

  void Check() const;
  void Load(OptionsReader& reader);
};

/// A detected corner: image position (px), FAST response and pyramid level (0 = full size).
struct DetectedKeypoint {
  cv::Point2f pt;
  float response = 0;
  int level = 0;
};

/// Grid-bucketed FAST detector. Stateless apart from its options; thread-compatible.
class GridDetector {
 public:
  explicit GridDetector(const GridDetectorOptions& options);

  /// Detects new keypoints in `grey` (CV_8UC1). Each cell gets up to its quota
  /// (target_count / cells, rounded up) minus the `existing` points already in it; the budget
  /// left by textureless cells then goes to the strongest remaining corners anywhere. New
  /// points keep min_distance_px from existing points and from each other.
  std::vector<DetectedKeypoint> Detect(const cv::Mat& grey,
                                       std::span<const cv::Point2f> existing) const;

  /// Grid cell index (row-major) of an image point, or -1 outside the image.
  int CellOf(const cv::Point2f& pt, const cv::Size& image_size) const;
  int num_cells() const { return options_.grid_cols * options_.grid_rows; }
  const GridDetectorOptions& options() const { return options_; }

 private:
  GridDetectorOptions options_;
};

}  // namespace cslam
