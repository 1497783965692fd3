#pragma once
// Simple line charts for the benchmark sweeps (accuracy and VI against noise or chunk
// length), drawn with OpenCV: axes with ticks and labels, one coloured polyline with markers
// per series, and a legend.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace cslam {

/// One polyline of a chart.
struct ChartSeries {
  std::string label;
  std::vector<double> x, y;
  cv::Scalar color_bgr{0, 0, 0};
};

/// A chart's content and axes; y_min/y_max NaN = fit to the data.
struct LineChart {
  std::string title, x_label, y_label;
  std::vector<ChartSeries> series;
  double y_min = std::numeric_limits<double>::quiet_NaN();
  double y_max = std::numeric_limits<double>::quiet_NaN();
};

/// Renders `chart` into a BGR image of the given size.
cv::Mat RenderLineChart(const LineChart& chart, int width = 900, int height = 600);

/// A "nice" tick step (1, 2 or 5 × 10^k) giving about `target` ticks over `range`.
double NiceTickStep(double range, int target);

/// A tick label for `v` with as many decimals as `step` needs.
std::string FormatTick(double v, double step);

/// A distinct colour for series k (BGR).
cv::Scalar SeriesColor(int k);

}  // namespace cslam
