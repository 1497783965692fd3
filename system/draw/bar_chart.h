#pragma once
// Grouped bar charts for the benchmark suites (bench.png: per-drive camera ATE, one bar per
// system), drawn with OpenCV beside the line charts of line_chart.h: a y axis with ticks, one
// group of bars per category, a legend. A missing value leaves a gap marked "n/a".
#include <opencv2/core.hpp>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace cslam {

/// One system's bars: values[i] belongs to BarChart::categories[i] (unset = no bar).
struct BarSeries {
  std::string label;
  std::vector<std::optional<double>> values;
  cv::Scalar color_bgr{0, 0, 0};
};

/// A chart's content; y starts at 0 and y_max NaN = fit to the data.
struct BarChart {
  std::string title, y_label;
  std::vector<std::string> categories;
  std::vector<BarSeries> series;
  double y_max = std::numeric_limits<double>::quiet_NaN();
};

/// Renders `chart` into a BGR image of the given size (labels are ASCII: Hershey fonts).
cv::Mat RenderBarChart(const BarChart& chart, int width = 1000, int height = 600);

}  // namespace cslam
