#include "system/draw/annotate.h"

#include <algorithm>
#include <array>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace cslam {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kLegendTextScale = 0.5;
constexpr int kLegendPadding = 10;   // px inside the frame
constexpr int kLegendRowHeight = 22;  // px
constexpr int kLegendSampleWidth = 36;  // px of line sample
constexpr int kLegendGap = 8;        // px between sample and label
constexpr int kDashPx = 6;
// Pixels this far from the background (max channel difference) count as data, not grid.
constexpr int kDataContrast = 60;

cv::Scalar Bgr(const cv::Vec3b& rgb) { return cv::Scalar(rgb[2], rgb[1], rgb[0]); }

}  // namespace

void PutLabel(cv::Mat& image, const std::string& text, cv::Point anchor, TextAlign align,
              double scale, const cv::Vec3b& rgb) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  cv::Point origin = anchor;
  if (align == TextAlign::kCentre) origin.x -= size.width / 2;
  if (align == TextAlign::kRight) origin.x -= size.width;
  cv::putText(image, text, origin, kFont, scale, Bgr(rgb), 1, cv::LINE_AA);
}

void PutCornerLabel(cv::Mat& image, const std::string& text) {
  constexpr double kScale = 0.7;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, kScale, 1, &baseline);
  const cv::Point anchor(image.cols - 12, 12 + size.height);
  cv::rectangle(image, cv::Rect(anchor.x - size.width - 6, 6, size.width + 12, size.height + baseline + 12),
                cv::Scalar(255, 255, 255), cv::FILLED);
  PutLabel(image, text, anchor, TextAlign::kRight, kScale, {20, 20, 20});
}

cv::Size LegendSize(const std::vector<LegendEntry>& entries) {
  int text_width = 0;
  for (const auto& e : entries) {
    int baseline = 0;
    text_width =
        std::max(text_width, cv::getTextSize(e.label, kFont, kLegendTextScale, 1, &baseline).width);
  }
  return {2 * kLegendPadding + kLegendSampleWidth + kLegendGap + text_width,
          2 * kLegendPadding + kLegendRowHeight * static_cast<int>(entries.size()) - 6};
}

void DrawLegend(cv::Mat& image, const std::vector<LegendEntry>& entries, cv::Point top_left) {
  if (entries.empty()) return;
  const cv::Size size = LegendSize(entries);
  const cv::Rect box(top_left, size);
  cv::rectangle(image, box, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, box, cv::Scalar(160, 160, 160), 1);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    const int y = top_left.y + kLegendPadding + kLegendRowHeight * static_cast<int>(i) + 8;
    const int x0 = top_left.x + kLegendPadding;
    const int x1 = x0 + kLegendSampleWidth;
    switch (e.marker) {
      case LegendMarker::kLine:
        cv::line(image, {x0, y}, {x1, y}, Bgr(e.rgb), 2, cv::LINE_AA);
        break;
      case LegendMarker::kDashedLine:
        for (int x = x0; x < x1; x += 2 * kDashPx)
          cv::line(image, {x, y}, {std::min(x + kDashPx, x1), y}, Bgr(e.rgb), 2, cv::LINE_AA);
        break;
      case LegendMarker::kDot:
        cv::circle(image, {(x0 + x1) / 2, y}, 5, Bgr(e.rgb), cv::FILLED, cv::LINE_AA);
        break;
    }
    PutLabel(image, e.label, {x1 + kLegendGap, y + 5}, TextAlign::kLeft, kLegendTextScale);
  }
}

cv::Point EmptiestCorner(const cv::Mat& image, const cv::Rect& area, cv::Size size, int margin,
                         const cv::Vec3b& background_rgb) {
  const std::array<cv::Point, 4> corners = {
      cv::Point(area.x + margin, area.y + margin),
      cv::Point(area.x + area.width - margin - size.width, area.y + margin),
      cv::Point(area.x + margin, area.y + area.height - margin - size.height),
      cv::Point(area.x + area.width - margin - size.width,
                area.y + area.height - margin - size.height)};
  const cv::Vec3b background_bgr(background_rgb[2], background_rgb[1], background_rgb[0]);
  cv::Point best = corners[0];
  int best_count = std::numeric_limits<int>::max();
  for (const auto& c : corners) {
    const cv::Rect box = cv::Rect(c, size) & cv::Rect(0, 0, image.cols, image.rows);
    int count = 0;
    for (int v = box.y; v < box.y + box.height; ++v)
      for (int u = box.x; u < box.x + box.width; ++u)
        count += cv::norm(cv::Vec3i(image.at<cv::Vec3b>(v, u)) - cv::Vec3i(background_bgr),
                          cv::NORM_INF) > kDataContrast;
    if (count < best_count) {
      best_count = count;
      best = c;
    }
  }
  return best;
}

}  // namespace cslam
