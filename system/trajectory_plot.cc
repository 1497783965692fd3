#include "system/trajectory_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

#include "system/annotate.h"
#include "system/cluster_colors.h"
#include "system/gl_draw.h"
#include "system/offscreen_context.h"

namespace cslam {
namespace {

// Layout of the picture, px at the final resolution.
constexpr int kMarginLeft = 80;
constexpr int kMarginRight = 30;
constexpr int kMarginTop = 50;
constexpr int kMarginBottom = 60;
constexpr double kDataPadding = 0.06;     // fraction of the data extent left free on each side
constexpr double kMinExtentM = 2.0;       // smallest world extent shown, metres
constexpr double kTargetGridLines = 10.0;  // about this many grid lines across the wider axis
constexpr int kSupersampling = 2;         // GL renders this many times larger, then averages
constexpr float kLineWidthPx = 2.0f;
constexpr float kStartMarkerPx = 8.0f;
constexpr int kDashPx = 10;
const cv::Vec3b kWhite{255, 255, 255};
const cv::Vec3b kGridRgb{228, 228, 228};
const cv::Vec3b kAxisRgb{185, 185, 185};
const cv::Vec3b kFrameRgb{120, 120, 120};

/// The smallest of 1, 2, 5 x 10^k that is >= raw.
double NiceStep(double raw) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10.0 * magnitude;
}

std::string FormatMetres(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", std::abs(value) < 1e-9 ? 0.0 : value);
  return text;
}

}  // namespace

TopViewLayout ComputeTopViewLayout(const std::vector<RenderTrajectory>& trajectories, int width,
                                   int height) {
  TopViewLayout layout;
  layout.plot_left = kMarginLeft;
  layout.plot_top = kMarginTop;
  layout.plot_right = std::max(kMarginLeft + 1, width - kMarginRight);
  layout.plot_bottom = std::max(kMarginTop + 1, height - kMarginBottom);

  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x;
  double min_z = min_x, max_z = -min_x;
  for (const auto& t : trajectories) {
    for (const auto& p : t.positions) {
      if (!p.allFinite()) continue;
      min_x = std::min(min_x, p.x());
      max_x = std::max(max_x, p.x());
      min_z = std::min(min_z, p.z());
      max_z = std::max(max_z, p.z());
    }
  }
  if (!(min_x <= max_x)) min_x = max_x = min_z = max_z = 0.0;  // nothing to show
  const double centre_x = 0.5 * (min_x + max_x), centre_z = 0.5 * (min_z + max_z);
  const double extent_x = std::max(kMinExtentM, (max_x - min_x) * (1.0 + 2.0 * kDataPadding));
  const double extent_z = std::max(kMinExtentM, (max_z - min_z) * (1.0 + 2.0 * kDataPadding));
  const double plot_w = layout.plot_right - layout.plot_left;
  const double plot_h = layout.plot_bottom - layout.plot_top;
  layout.scale_px_per_m = std::min(plot_w / extent_x, plot_h / extent_z);
  layout.origin_u = 0.5 * (layout.plot_left + layout.plot_right) - layout.scale_px_per_m * centre_x;
  layout.origin_v = 0.5 * (layout.plot_top + layout.plot_bottom) + layout.scale_px_per_m * centre_z;
  layout.grid_step_m =
      NiceStep(std::max(plot_w, plot_h) / layout.scale_px_per_m / kTargetGridLines);
  return layout;
}

cv::Mat RenderTrajectoryTopView(const std::vector<RenderTrajectory>& trajectories, int width,
                                int height) {
  const TopViewLayout layout = ComputeTopViewLayout(trajectories, width, height);
  const int ss = kSupersampling;
  const double step = layout.grid_step_m;
  // World bounds of the plot area.
  const double x_lo = (layout.plot_left - layout.origin_u) / layout.scale_px_per_m;
  const double x_hi = (layout.plot_right - layout.origin_u) / layout.scale_px_per_m;
  const double z_lo = (layout.origin_v - layout.plot_bottom) / layout.scale_px_per_m;
  const double z_hi = (layout.origin_v - layout.plot_top) / layout.scale_px_per_m;
  const auto to_ss = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = layout.ToPixel(p);
    return Eigen::Vector3d(ss * (px.x() + 0.5) - 0.5, ss * (px.y() + 0.5) - 0.5, 0.0);
  };

  OffscreenContext context(width * ss, height * ss);
  gl::BeginFrame(kWhite, /*depth_test=*/false);
  gl::UsePixelCoordinates(width * ss, height * ss);

  // Grid, with the world axes slightly darker.
  std::vector<Eigen::Vector3d> grid, axes;
  for (double x = std::ceil(x_lo / step) * step; x <= x_hi; x += step) {
    auto& dst = std::abs(x) < 1e-9 * step ? axes : grid;
    dst.push_back(to_ss({x, 0, z_lo}));
    dst.push_back(to_ss({x, 0, z_hi}));
  }
  for (double z = std::ceil(z_lo / step) * step; z <= z_hi; z += step) {
    auto& dst = std::abs(z) < 1e-9 * step ? axes : grid;
    dst.push_back(to_ss({x_lo, 0, z}));
    dst.push_back(to_ss({x_hi, 0, z}));
  }
  gl::DrawLines(grid, {.rgb = kGridRgb, .width_px = float(ss)});
  gl::DrawLines(axes, {.rgb = kAxisRgb, .width_px = float(ss)});

  // Ground truth first so the estimates stay on top.
  for (bool dashed_pass : {true, false}) {
    for (const auto& t : trajectories) {
      if (t.dashed != dashed_pass || t.positions.empty()) continue;
      std::vector<Eigen::Vector3d> line;
      line.reserve(t.positions.size());
      for (const auto& p : t.positions)
        if (p.allFinite()) line.push_back(to_ss(p));
      const gl::LineStyle style{.rgb = TrajectoryColor(t.cluster),
                                .width_px = kLineWidthPx * ss,
                                .dashed = t.dashed,
                                .dash_px = kDashPx * ss};
      gl::DrawLineStrip(line, style);
      if (!t.dashed && !line.empty())
        gl::DrawPoints({line.front()}, TrajectoryColor(t.cluster), kStartMarkerPx * ss);
    }
  }
  cv::Mat big = context.ReadPixels();
  cv::Mat image;
  cv::resize(big, image, cv::Size(width, height), 0, 0, cv::INTER_AREA);

  // Frame, tick labels and axis titles.
  const cv::Rect plot(layout.plot_left, layout.plot_top, layout.plot_right - layout.plot_left,
                      layout.plot_bottom - layout.plot_top);
  for (double x = std::ceil(x_lo / step) * step; x <= x_hi; x += step) {
    const int u = static_cast<int>(std::lround(layout.ToPixel({x, 0, 0}).x()));
    PutLabel(image, FormatMetres(x), {u, layout.plot_bottom + 20}, TextAlign::kCentre);
  }
  for (double z = std::ceil(z_lo / step) * step; z <= z_hi; z += step) {
    const int v = static_cast<int>(std::lround(layout.ToPixel({0, 0, z}).y()));
    PutLabel(image, FormatMetres(z), {layout.plot_left - 8, v + 5}, TextAlign::kRight);
  }
  PutLabel(image, "x [m]", {(layout.plot_left + layout.plot_right) / 2, layout.plot_bottom + 45},
           TextAlign::kCentre, 0.55);
  PutLabel(image, "z [m]", {layout.plot_left - 8, layout.plot_top - 12}, TextAlign::kRight, 0.55);
  PutLabel(image, "Trajectories, top view (x-z plane of the first camera frame)",
           {(layout.plot_left + layout.plot_right) / 2, 30}, TextAlign::kCentre, 0.65);

  // Scale bar: one grid step, bottom right of the plot.
  const int bar_px = static_cast<int>(std::lround(step * layout.scale_px_per_m));
  const cv::Point bar_right(layout.plot_right - 20, layout.plot_bottom - 20);
  const cv::Point bar_left(bar_right.x - bar_px, bar_right.y);
  const cv::Rect bar_box(bar_left.x - 10, bar_left.y - 30, bar_px + 20, 40);
  cv::rectangle(image, bar_box & plot, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::line(image, bar_left, bar_right, cv::Scalar(40, 40, 40), 3, cv::LINE_AA);
  cv::line(image, bar_left + cv::Point(0, -6), bar_left + cv::Point(0, 6), cv::Scalar(40, 40, 40),
           2, cv::LINE_AA);
  cv::line(image, bar_right + cv::Point(0, -6), bar_right + cv::Point(0, 6),
           cv::Scalar(40, 40, 40), 2, cv::LINE_AA);
  PutLabel(image, FormatMetres(step) + " m", {(bar_left.x + bar_right.x) / 2, bar_left.y - 12},
           TextAlign::kCentre);
  cv::rectangle(image, plot, cv::Scalar(kFrameRgb[2], kFrameRgb[1], kFrameRgb[0]), 1);

  // Legend in the emptiest corner of the plot.
  std::vector<LegendEntry> entries;
  for (const auto& t : trajectories) {
    if (t.label.empty()) continue;
    entries.push_back({t.label, TrajectoryColor(t.cluster),
                       t.dashed ? LegendMarker::kDashedLine : LegendMarker::kLine});
  }
  // An online map can hold dozens of clusters: keep the legend inside the plot, naming the
  // first entries (camera first) and counting the rest.
  int left_out = 0;
  while (entries.size() > 2 && LegendSize(entries).height > plot.height - 24) {
    entries.pop_back();
    if (left_out++ == 0) entries.pop_back(), ++left_out;  // room for the summary line
  }
  if (left_out > 0)
    entries.push_back({"+ " + std::to_string(left_out) + " more clusters", cv::Vec3b(150, 150, 150),
                       LegendMarker::kLine});
  if (!entries.empty()) {
    const cv::Size legend_size = LegendSize(entries);
    DrawLegend(image, entries, EmptiestCorner(image, plot, legend_size, 12, kWhite));
  }
  return image;
}

}  // namespace cslam
