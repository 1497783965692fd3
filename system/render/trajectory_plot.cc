#include "system/render/trajectory_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"
#include "system/render/gl_draw.h"
#include "system/render/offscreen_context.h"

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
constexpr int kLegendMargin = 12;  // px between the legend and the plot's frame
// A legend column beside the plot may cost at most this share of the drawing's scale.
constexpr double kMinLegendColumnScale = 0.75;
constexpr int kScaleBarPadding = 10;  // px of white box left and right of the bar
constexpr int kScaleBarHeight = 40;   // px of white box, label included
constexpr int kScaleBarMargin = 10;   // px between the box and the plot's frame
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

/// The plot area's layout for a given plot rectangle (no legend yet).
TopViewLayout FitPlot(const std::vector<RenderTrajectory>& trajectories, int left, int top,
                      int right, int bottom) {
  TopViewLayout layout;
  layout.plot_left = left;
  layout.plot_top = top;
  layout.plot_right = std::max(left + 1, right);
  layout.plot_bottom = std::max(top + 1, bottom);

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

cv::Rect PlotRect(const TopViewLayout& layout) {
  return {layout.plot_left, layout.plot_top, layout.plot_right - layout.plot_left,
          layout.plot_bottom - layout.plot_top};
}

/// The four places for a box of `size` in the plot's corners, `margin` px inside its frame, in
/// the order of preference: top left, top right, bottom left, bottom right.
std::array<cv::Rect, 4> CornerBoxes(const cv::Rect& plot, cv::Size size, int margin) {
  const int left = plot.x + margin, right = plot.br().x - margin - size.width;
  const int top = plot.y + margin, bottom = plot.br().y - margin - size.height;
  return {cv::Rect({left, top}, size), cv::Rect({right, top}, size),
          cv::Rect({left, bottom}, size), cv::Rect({right, bottom}, size)};
}

/// The legend's rows: every labelled trajectory, camera first. An online map can hold dozens
/// of clusters, so past `max_height` px the last rows give way to a count of the rest.
std::vector<LegendEntry> LegendEntries(const std::vector<RenderTrajectory>& trajectories,
                                       int max_height) {
  std::vector<LegendEntry> entries;
  for (const auto& t : trajectories) {
    if (t.label.empty()) continue;
    entries.push_back({t.label, TrajectoryColor(t.cluster),
                       t.dashed ? LegendMarker::kDashedLine : LegendMarker::kLine});
  }
  int left_out = 0;
  while (entries.size() > 2 && LegendSize(entries).height > max_height) {
    entries.pop_back();
    if (left_out++ == 0) entries.pop_back(), ++left_out;  // room for the summary line
  }
  if (left_out > 0)
    entries.push_back({"+ " + std::to_string(left_out) + " more clusters", cv::Vec3b(150, 150, 150),
                       LegendMarker::kLine});
  return entries;
}

/// The legend's rows for a plot `plot_height` px tall (LegendEntries with its room).
std::vector<LegendEntry> LegendEntriesFor(const std::vector<RenderTrajectory>& trajectories,
                                          int plot_height) {
  return LegendEntries(trajectories, plot_height - 2 * kLegendMargin);
}

/// How many points, sampled every pixel along the drawn trajectories (lines and start markers,
/// widened by their half width), fall inside `box`.
int TrajectoryPixelsIn(const std::vector<RenderTrajectory>& trajectories,
                       const TopViewLayout& layout, const cv::Rect& box) {
  const double pad = 0.5 * kStartMarkerPx + 1.0;
  const cv::Rect2d area(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad);
  const auto inside = [&](const Eigen::Vector2d& px) { return area.contains({px.x(), px.y()}); };
  int count = 0;
  for (const auto& t : trajectories) {
    bool first = true;
    Eigen::Vector2d last = Eigen::Vector2d::Zero();
    for (const auto& p : t.positions) {
      if (!p.allFinite()) {  // the line breaks here
        first = true;
        continue;
      }
      const Eigen::Vector2d px = layout.ToPixel(p);
      if (first) {
        count += inside(px);
      } else {
        const int steps = std::max(1, static_cast<int>(std::ceil((px - last).norm())));
        for (int i = 1; i <= steps; ++i) count += inside(last + (px - last) * (double(i) / steps));
      }
      last = px;
      first = false;
    }
  }
  return count;
}

/// The plot and the legend of ComputeTopViewLayout.
TopViewLayout PlaceLegend(const std::vector<RenderTrajectory>& trajectories, int width,
                          int height) {
  const int right = width - kMarginRight, bottom = height - kMarginBottom;
  TopViewLayout layout = FitPlot(trajectories, kMarginLeft, kMarginTop, right, bottom);
  const cv::Rect plot = PlotRect(layout);
  const std::vector<LegendEntry> entries = LegendEntriesFor(trajectories, plot.height);
  if (entries.empty()) return layout;
  const cv::Size size = LegendSize(entries);

  // A corner of the plot that no trajectory crosses.
  int best_count = std::numeric_limits<int>::max();
  for (const cv::Rect& box : CornerBoxes(plot, size, kLegendMargin)) {
    const int count = TrajectoryPixelsIn(trajectories, layout, box);
    if (count < best_count) {
      best_count = count;
      layout.legend = box;
    }
  }
  if (best_count == 0) return layout;

  // Every corner would hide data (a long drive with many clusters): the legend takes a column
  // beside the plot, unless the narrower plot would shrink the drawing by more than a quarter.
  const int narrowed_right = right - size.width - kLegendMargin;
  const TopViewLayout narrowed =
      FitPlot(trajectories, kMarginLeft, kMarginTop, narrowed_right, bottom);
  if (narrowed_right - kMarginLeft < 100 ||
      narrowed.scale_px_per_m < kMinLegendColumnScale * layout.scale_px_per_m)
    return layout;
  layout = narrowed;
  layout.legend = cv::Rect(cv::Point(narrowed_right + kLegendMargin, kMarginTop), size);
  return layout;
}

}  // namespace

TopViewLayout ComputeTopViewLayout(const std::vector<RenderTrajectory>& trajectories, int width,
                                   int height) {
  TopViewLayout layout = PlaceLegend(trajectories, width, height);
  // The scale bar (one grid step) goes to the corner with the fewest trajectory pixels, off
  // the legend, bottom right when it is free.
  const int bar_px = static_cast<int>(std::lround(layout.grid_step_m * layout.scale_px_per_m));
  const cv::Rect plot = PlotRect(layout);
  const auto boxes = CornerBoxes(plot, {bar_px + 2 * kScaleBarPadding, kScaleBarHeight},
                                 kScaleBarMargin);
  long best_count = std::numeric_limits<long>::max();
  for (int i : {3, 2, 1, 0}) {
    const long count = TrajectoryPixelsIn(trajectories, layout, boxes[i]) +
                       1000L * (boxes[i] & layout.legend).area();
    if (count < best_count) {
      best_count = count;
      layout.scale_bar = boxes[i] & plot;
    }
  }
  return layout;
}

cv::Mat RenderTrajectoryTopView(const std::vector<RenderTrajectory>& trajectories, int width,
                                int height, const std::string& title) {
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

  // Ground truth last, dashed: where an estimate lies on it (a good one does) the truth stays
  // visible and the estimate shows through its gaps; drawn first it vanished under the line.
  for (bool dashed_pass : {false, true}) {
    for (const auto& t : trajectories) {
      if (t.dashed != dashed_pass || t.positions.empty()) continue;
      const gl::LineStyle style{.rgb = TrajectoryColor(t.cluster),
                                .width_px = kLineWidthPx * ss,
                                .dashed = t.dashed,
                                .dash_px = kDashPx * ss};
      // One strip per stretch between non-finite positions (frames nothing was seen at).
      std::vector<Eigen::Vector3d> line;
      std::optional<Eigen::Vector3d> start;
      auto flush = [&] {
        if (!line.empty()) gl::DrawLineStrip(line, style);
        line.clear();
      };
      for (const auto& p : t.positions) {
        if (!p.allFinite()) {
          flush();
          continue;
        }
        line.push_back(to_ss(p));
        if (!start) start = line.back();
      }
      flush();
      if (!t.dashed && start)
        gl::DrawPoints({*start}, TrajectoryColor(t.cluster), kStartMarkerPx * ss);
    }
  }
  cv::Mat big = context.ReadPixels();
  cv::Mat image;
  cv::resize(big, image, cv::Size(width, height), 0, 0, cv::INTER_AREA);

  // Frame, tick labels and axis titles.
  const cv::Rect plot = PlotRect(layout);
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
  // The title spans the plot and a legend column beside it.
  const int title_right = std::max(layout.plot_right, layout.legend.br().x);
  PutLabel(image, title, {(layout.plot_left + title_right) / 2, 30}, TextAlign::kCentre, 0.65);

  // Scale bar: one grid step.
  const cv::Rect& bar_box = layout.scale_bar;
  const cv::Point bar_left(bar_box.x + kScaleBarPadding, bar_box.y + kScaleBarHeight - 10);
  const cv::Point bar_right(bar_box.br().x - kScaleBarPadding, bar_left.y);
  cv::rectangle(image, bar_box, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::line(image, bar_left, bar_right, cv::Scalar(40, 40, 40), 3, cv::LINE_AA);
  cv::line(image, bar_left + cv::Point(0, -6), bar_left + cv::Point(0, 6), cv::Scalar(40, 40, 40),
           2, cv::LINE_AA);
  cv::line(image, bar_right + cv::Point(0, -6), bar_right + cv::Point(0, 6),
           cv::Scalar(40, 40, 40), 2, cv::LINE_AA);
  PutLabel(image, FormatMetres(step) + " m", {(bar_left.x + bar_right.x) / 2, bar_left.y - 12},
           TextAlign::kCentre);
  cv::rectangle(image, plot, cv::Scalar(kFrameRgb[2], kFrameRgb[1], kFrameRgb[0]), 1);

  if (!layout.legend.empty())
    DrawLegend(image, LegendEntriesFor(trajectories, plot.height), layout.legend.tl());
  return image;
}

}  // namespace cslam
