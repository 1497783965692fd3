#include "system/draw/bar_chart.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "system/draw/line_chart.h"

namespace cslam {

cv::Mat RenderBarChart(const BarChart& chart, int width, int height) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 30, top = 60 + 20 * static_cast<int>(chart.series.size()), bottom = 90;
  const cv::Rect plot(left, top, width - left - right, std::max(40, height - top - bottom));
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  const int font = cv::FONT_HERSHEY_SIMPLEX;

  double y1 = 0;
  for (const BarSeries& s : chart.series)
    for (const auto& v : s.values)
      if (v && std::isfinite(*v)) y1 = std::max(y1, *v);
  if (std::isfinite(chart.y_max)) y1 = chart.y_max;
  if (!(y1 > 0)) y1 = 1;
  const double ys = NiceTickStep(y1, 6);
  y1 = std::ceil(y1 / ys) * ys;
  auto to_y = [&](double y) {
    return plot.y + plot.height - static_cast<int>(std::lround(std::min(y, y1) / y1 * plot.height));
  };
  for (double y = 0; y <= y1 + 1e-9 * ys; y += ys) {
    const int py = to_y(y);
    cv::line(img, {plot.x, py}, {plot.x + plot.width, py}, grid, 1, cv::LINE_AA);
    const std::string t = FormatTick(y, ys);
    cv::putText(img, t, {plot.x - 10 - 9 * static_cast<int>(t.size()), py + 5}, font, 0.45, ink, 1,
                cv::LINE_AA);
  }

  const int groups = std::max<int>(1, static_cast<int>(chart.categories.size()));
  const int bars = std::max<int>(1, static_cast<int>(chart.series.size()));
  const double group_w = static_cast<double>(plot.width) / groups;
  const double bar_w = 0.8 * group_w / bars;
  for (int g = 0; g < static_cast<int>(chart.categories.size()); ++g) {
    const double gx = plot.x + g * group_w + 0.1 * group_w;
    for (int b = 0; b < static_cast<int>(chart.series.size()); ++b) {
      const BarSeries& s = chart.series[b];
      const int x0 = static_cast<int>(std::lround(gx + b * bar_w));
      const int x1 = static_cast<int>(std::lround(gx + (b + 1) * bar_w)) - 2;
      if (g < static_cast<int>(s.values.size()) && s.values[g] && std::isfinite(*s.values[g])) {
        cv::rectangle(img, {x0, to_y(*s.values[g])}, {x1, to_y(0)}, s.color_bgr, cv::FILLED);
        if (*s.values[g] > y1)  // clipped: mark the top
          cv::line(img, {x0, plot.y + 3}, {x1, plot.y + 3}, ink, 2);
      } else {
        cv::putText(img, "n/a", {x0, to_y(0) - 4}, font, 0.35, ink, 1, cv::LINE_AA);
      }
    }
    // The category under its group, shortened to fit.
    std::string label = chart.categories[g];
    const int max_chars = std::max(4, static_cast<int>(group_w / 8));
    if (static_cast<int>(label.size()) > max_chars) label = label.substr(label.size() - max_chars);
    cv::putText(img, label, {static_cast<int>(gx), plot.y + plot.height + 22}, font, 0.42, ink, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, plot, ink, 1);

  cv::putText(img, chart.title, {left, 35}, font, 0.7, ink, 2, cv::LINE_AA);
  if (!chart.y_label.empty()) {
    cv::Mat strip(30, plot.height, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(strip, chart.y_label,
                {std::max(0, plot.height / 2 - 5 * static_cast<int>(chart.y_label.size())), 21}, font,
                0.55, ink, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(strip, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    rotated.copyTo(img(cv::Rect(8, plot.y, rotated.cols, rotated.rows)));
  }
  // Legend above the plot, one line per system.
  int ly = 60;
  for (const BarSeries& s : chart.series) {
    cv::rectangle(img, {left, ly - 11}, {left + 22, ly + 1}, s.color_bgr, cv::FILLED);
    cv::putText(img, s.label, {left + 30, ly}, font, 0.45, ink, 1, cv::LINE_AA);
    ly += 20;
  }
  return img;
}

}  // namespace cslam
