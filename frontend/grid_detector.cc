#include "frontend/grid_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>

#include "core/options_reader.h"

namespace cslam {

void GridDetectorOptions::Check() const {
  CheckOption(target_count > 0, "target_count", "must be > 0", target_count);
  CheckOption(grid_cols > 0, "grid_cols", "must be > 0", grid_cols);
  CheckOption(grid_rows > 0, "grid_rows", "must be > 0", grid_rows);
  CheckOption(fast_threshold >= 1 && fast_threshold <= 255, "fast_threshold",
              "must be in [1, 255] grey levels", fast_threshold);
  CheckOption(min_distance_px > 0, "min_distance_px", "must be > 0 px", min_distance_px);
  CheckOption(border_px >= 16, "border_px", "must be >= 16 px (half the ORB patch)", border_px);
}

void GridDetectorOptions::Load(OptionsReader& reader) {
  reader.Read("target_count", &target_count);
  reader.Read("grid_cols", &grid_cols);
  reader.Read("grid_rows", &grid_rows);
  reader.Read("fast_threshold", &fast_threshold);
  reader.Read("min_distance_px", &min_distance_px);
  reader.Read("border_px", &border_px);
}

GridDetector::GridDetector(const GridDetectorOptions& options) : options_(options) {
  options_.Check();
}

int GridDetector::CellOf(const cv::Point2f& pt, const cv::Size& size) const {
  if (!(pt.x >= 0 && pt.y >= 0 && pt.x < size.width && pt.y < size.height)) return -1;
  const int c =
      std::min(options_.grid_cols - 1, static_cast<int>(pt.x * options_.grid_cols / size.width));
  const int r =
      std::min(options_.grid_rows - 1, static_cast<int>(pt.y * options_.grid_rows / size.height));
  return r * options_.grid_cols + c;
}

namespace {

/// Occupancy bitmap with bins of min_distance: a point is refused when its bin or one of the
/// 8 neighbouring bins holds a point closer than min_distance.
class SpacingMap {
 public:
  SpacingMap(const cv::Size& size, double min_distance)
      : bin_(min_distance),
        cols_(static_cast<int>(std::ceil(size.width / min_distance)) + 1),
        rows_(static_cast<int>(std::ceil(size.height / min_distance)) + 1),
        bins_(static_cast<size_t>(cols_) * rows_) {}

  bool Free(const cv::Point2f& p) const {
    const int c = static_cast<int>(p.x / bin_), r = static_cast<int>(p.y / bin_);
    const double d2 = bin_ * bin_;
    for (int rr = std::max(0, r - 1); rr <= std::min(rows_ - 1, r + 1); ++rr)
      for (int cc = std::max(0, c - 1); cc <= std::min(cols_ - 1, c + 1); ++cc)
        for (const cv::Point2f& q : bins_[static_cast<size_t>(rr) * cols_ + cc]) {
          const double dx = q.x - p.x, dy = q.y - p.y;
          if (dx * dx + dy * dy < d2) return false;
        }
    return true;
  }
  void Insert(const cv::Point2f& p) {
    const int c = std::clamp(static_cast<int>(p.x / bin_), 0, cols_ - 1);
    const int r = std::clamp(static_cast<int>(p.y / bin_), 0, rows_ - 1);
    bins_[static_cast<size_t>(r) * cols_ + c].push_back(p);
  }

 private:
  double bin_;
  int cols_, rows_;
  std::vector<std::vector<cv::Point2f>> bins_;
};

}  // namespace

std::vector<DetectedKeypoint> GridDetector::Detect(const cv::Mat& grey,
                                                   std::span<const cv::Point2f> existing) const {
  const cv::Size size = grey.size();
  const int b = options_.border_px;
  std::vector<DetectedKeypoint> out;
  if (size.width <= 2 * b || size.height <= 2 * b) return out;

  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey(cv::Rect(b, b, size.width - 2 * b, size.height - 2 * b)), corners,
           options_.fast_threshold, /*nonmaxSuppression=*/true);
  // Strongest first, so both the per-cell pass and the top-up pass are greedy by response.
  std::sort(corners.begin(), corners.end(),
            [](const cv::KeyPoint& a, const cv::KeyPoint& c) { return a.response > c.response; });

  SpacingMap spacing(size, options_.min_distance_px);
  std::vector<int> in_cell(num_cells(), 0);
  for (const cv::Point2f& p : existing) {
    spacing.Insert(p);
    const int cell = CellOf(p, size);
    if (cell >= 0) ++in_cell[cell];
  }
  const int quota = (options_.target_count + num_cells() - 1) / num_cells();
  int budget = options_.target_count - static_cast<int>(existing.size());
  if (budget <= 0) return out;

  std::vector<char> taken(corners.size(), 0);
  for (size_t i = 0; i < corners.size() && budget > 0; ++i) {
    const cv::Point2f p(corners[i].pt.x + b, corners[i].pt.y + b);
    const int cell = CellOf(p, size);
    if (cell < 0 || in_cell[cell] >= quota || !spacing.Free(p)) continue;
    spacing.Insert(p);
    ++in_cell[cell];
    taken[i] = 1;
    out.push_back({p, corners[i].response, 0});
    --budget;
  }
  // Top-up: what textureless cells (sky, road) could not use goes to the best corners left.
  for (size_t i = 0; i < corners.size() && budget > 0; ++i) {
    if (taken[i]) continue;
    const cv::Point2f p(corners[i].pt.x + b, corners[i].pt.y + b);
    if (!spacing.Free(p)) continue;
    spacing.Insert(p);
    out.push_back({p, corners[i].response, 0});
    --budget;
  }
  return out;
}

}  // namespace cslam
