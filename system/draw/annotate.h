#pragma once
// Text and legends drawn with OpenCV on rendered images (after the GL read-back, so text stays
// crisp at the final resolution). Images are 8-bit BGR; colours passed in are RGB.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace cslam {

/// How a legend entry shows its colour.
enum class LegendMarker { kLine, kDashedLine, kDot };

/// One row of a legend.
struct LegendEntry {
  std::string label;
  cv::Vec3b rgb{0, 0, 0};
  LegendMarker marker = LegendMarker::kLine;
};

/// Horizontal anchoring of a text label relative to its anchor point.
enum class TextAlign { kLeft, kCentre, kRight };

/// Draws `text` in dark grey with its baseline-centre/left/right at `anchor`, anti-aliased.
void PutLabel(cv::Mat& image, const std::string& text, cv::Point anchor, TextAlign align,
              double scale = 0.5, const cv::Vec3b& rgb = {50, 50, 50});

/// Writes `text` on a white box in the top-right corner (a picture's frame number: it reads on
/// a camera image too, and stays clear of the legends drawn top-left).
void PutCornerLabel(cv::Mat& image, const std::string& text);

/// Pixel size of the legend box DrawLegend draws for `entries`.
cv::Size LegendSize(const std::vector<LegendEntry>& entries);

/// Draws a framed white legend box with its top-left corner at `top_left`.
void DrawLegend(cv::Mat& image, const std::vector<LegendEntry>& entries, cv::Point top_left);

/// Of the four corners of `area` (inset by `margin`), the top-left point of a box of `size`
/// that covers the fewest data pixels (clearly different from `background_rgb`; faint grid lines
/// do not count), so legends stay off the data.
cv::Point EmptiestCorner(const cv::Mat& image, const cv::Rect& area, cv::Size size, int margin,
                         const cv::Vec3b& background_rgb);

}  // namespace cslam
