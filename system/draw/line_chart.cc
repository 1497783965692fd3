#include "system/draw/line_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace cslam {

double NiceTickStep(double range, int target) {
  if (!(range > 0)) return 1.0;
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double nice = norm < 1.5 ? 1 : (norm < 3 ? 2 : (norm < 7 ? 5 : 10));
  return nice * mag;
}

std::string FormatTick(double v, double step) {
  char buf[32];
  const int decimals = step >= 1 ? 0 : std::min(6, static_cast<int>(std::ceil(-std::log10(step))));
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

cv::Scalar SeriesColor(int k) {
  static const cv::Scalar kColors[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},
                                       {40, 39, 214},  {189, 103, 148}, {75, 86, 140},
                                       {194, 119, 227}, {127, 127, 127}};
  return kColors[k % 8];
}

cv::Mat RenderLineChart(const LineChart& chart, int width, int height) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 30, top = 60, bottom = 70;
  const cv::Rect plot(left, top, width - left - right, height - top - bottom);

  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : chart.series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (std::isfinite(chart.y_min)) y0 = chart.y_min;
  if (std::isfinite(chart.y_max)) y1 = chart.y_max;
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  const double ypad = std::isfinite(chart.y_min) && std::isfinite(chart.y_max) ? 0 : 0.05 * (y1 - y0);
  y0 -= ypad;
  y1 += ypad;

  auto to_px = [&](double x, double y) {
    return cv::Point(plot.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * plot.width)),
                     plot.y + plot.height -
                         static_cast<int>(std::lround((y - y0) / (y1 - y0) * plot.height)));
  };
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  const int font = cv::FONT_HERSHEY_SIMPLEX;

  const double xs = NiceTickStep(x1 - x0, 8), ys = NiceTickStep(y1 - y0, 6);
  for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9 * xs; x += xs) {
    const cv::Point p = to_px(x, y0);
    cv::line(img, {p.x, plot.y}, {p.x, plot.y + plot.height}, grid, 1, cv::LINE_AA);
    const std::string t = FormatTick(x, xs);
    cv::putText(img, t, {p.x - 4 * static_cast<int>(t.size()), plot.y + plot.height + 22}, font,
                0.45, ink, 1, cv::LINE_AA);
  }
  for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys) {
    const cv::Point p = to_px(x0, y);
    cv::line(img, {plot.x, p.y}, {plot.x + plot.width, p.y}, grid, 1, cv::LINE_AA);
    const std::string t = FormatTick(y, ys);
    cv::putText(img, t, {plot.x - 10 - 9 * static_cast<int>(t.size()), p.y + 5}, font, 0.45, ink,
                1, cv::LINE_AA);
  }
  cv::rectangle(img, plot, ink, 1);

  for (const auto& s : chart.series) {
    std::vector<cv::Point> pts;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) pts.push_back(to_px(s.x[i], s.y[i]));
    if (pts.size() >= 2) cv::polylines(img, pts, false, s.color_bgr, 2, cv::LINE_AA);
    for (const auto& p : pts) cv::circle(img, p, 4, s.color_bgr, cv::FILLED, cv::LINE_AA);
  }

  cv::putText(img, chart.title, {left, 35}, font, 0.7, ink, 2, cv::LINE_AA);
  cv::putText(img, chart.x_label, {plot.x + plot.width / 2 - 4 * static_cast<int>(chart.x_label.size()), height - 20},
              font, 0.55, ink, 1, cv::LINE_AA);
  // Vertical y label: draw horizontally into a strip, rotate it.
  if (!chart.y_label.empty()) {
    cv::Mat strip(30, plot.height, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(strip, chart.y_label, {std::max(0, plot.height / 2 - 5 * static_cast<int>(chart.y_label.size())), 21},
                font, 0.55, ink, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(strip, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    rotated.copyTo(img(cv::Rect(8, plot.y, rotated.cols, rotated.rows)));
  }
  // Legend, top right inside the plot.
  int ly = plot.y + 20;
  int lw = 0;
  for (const auto& s : chart.series) lw = std::max(lw, static_cast<int>(s.label.size()) * 9 + 40);
  const int lx = plot.x + plot.width - lw - 10;
  if (!chart.series.empty()) {
    cv::rectangle(img, {lx - 8, plot.y + 6}, {lx + lw, plot.y + 12 + 20 * static_cast<int>(chart.series.size())},
                  cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(img, {lx - 8, plot.y + 6}, {lx + lw, plot.y + 12 + 20 * static_cast<int>(chart.series.size())},
                  grid, 1);
  }
  for (const auto& s : chart.series) {
    cv::line(img, {lx, ly - 5}, {lx + 25, ly - 5}, s.color_bgr, 2, cv::LINE_AA);
    cv::putText(img, s.label, {lx + 32, ly}, font, 0.45, ink, 1, cv::LINE_AA);
    ly += 20;
  }
  return img;
}

}  // namespace cslam
