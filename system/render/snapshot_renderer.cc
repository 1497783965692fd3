#include "system/render/snapshot_renderer.h"

#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/logging.h"
#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"
#include "system/render/gl_draw.h"
#include "system/render/offscreen_context.h"

namespace cslam {
namespace {

const cv::Vec3b kWhite{255, 255, 255};
const cv::Vec3b kGroundGridRgb{232, 232, 232};
const cv::Vec3b kFrustumRgb{0, 0, 0};
constexpr float kTrajectoryWidthPx = 2.0f;
constexpr float kFrustumWidthPx = 1.5f;
constexpr int kDashPx = 8;
constexpr int kLegendMargin = 12;  // px from the picture's corner

std::string ClusterName(int cluster) {
  if (cluster < 0) return "outlier";
  if (cluster == 0) return "static";
  return "object " + std::to_string(cluster);
}

/// Draws points grouped by cluster: unclustered first, then static, then moving clusters.
void DrawClusteredPoints(const std::vector<RenderPoint>& points, float size_px) {
  std::map<int, std::vector<Eigen::Vector3d>> by_cluster;
  for (const auto& p : points)
    if (p.p.allFinite()) by_cluster[std::max(p.cluster, -1)].push_back(p.p);
  for (const auto& [cluster, positions] : by_cluster)
    gl::DrawPoints(positions, ColorForCluster(cluster), size_px);
}

std::vector<Eigen::Vector3d> FrustumSegments(const Pose& world_from_cam, const StereoCamera& cam,
                                             double depth) {
  const auto corner = [&](double u, double v) {
    return world_from_cam *
           Eigen::Vector3d((u - cam.cx) / cam.fx * depth, (v - cam.cy) / cam.fy * depth, depth);
  };
  const double w = cam.width > 0 ? cam.width - 1 : 2 * cam.cx;
  const double h = cam.height > 0 ? cam.height - 1 : 2 * cam.cy;
  const Eigen::Vector3d c = world_from_cam.translation();
  const Eigen::Vector3d a = corner(0, 0), b = corner(w, 0), d = corner(w, h), e = corner(0, h);
  return {c, a, c, b, c, d, c, e, a, b, b, d, d, e, e, a};
}

std::vector<Eigen::Vector3d> GroundGridSegments(const Pose& world_from_cam,
                                                const SnapshotOptions& o) {
  std::vector<Eigen::Vector3d> segments;
  const double y = o.ground_below_m;
  const int n = static_cast<int>(std::floor(o.grid_extent_m / o.grid_step_m));
  const double e = n * o.grid_step_m;
  for (int i = -n; i <= n; ++i) {
    const double s = i * o.grid_step_m;
    segments.push_back(world_from_cam * Eigen::Vector3d(s, y, -e));
    segments.push_back(world_from_cam * Eigen::Vector3d(s, y, e));
    segments.push_back(world_from_cam * Eigen::Vector3d(-e, y, s));
    segments.push_back(world_from_cam * Eigen::Vector3d(e, y, s));
  }
  return segments;
}

cv::Mat Render(const std::vector<RenderPoint>& landmarks, const std::vector<RenderPoint>& dense,
               const Pose& world_from_cam, const StereoCamera& cam,
               const std::vector<RenderTrajectory>& recent, const SnapshotOptions& o) {
  o.Check();
  const int ss = o.supersampling;
  const RenderView view = SnapshotView(world_from_cam, o).Scaled(ss);
  OffscreenContext context(view.width, view.height);
  gl::BeginFrame(kWhite, /*depth_test=*/false);
  gl::UseView(view);
  // The ground grid is only a backdrop: drawn without depth so it never hides a point.
  if (o.ground_below_m > 0)
    gl::DrawLines(GroundGridSegments(world_from_cam, o), {.rgb = kGroundGridRgb, .width_px = 1.0f * ss});
  gl::EnableDepthTest(true);
  DrawClusteredPoints(dense, static_cast<float>(o.dense_point_size_px * ss));
  DrawClusteredPoints(landmarks, static_cast<float>(o.landmark_size_px * ss));
  for (const auto& t : recent) {
    std::vector<Eigen::Vector3d> line;
    for (const auto& p : t.positions)
      if (p.allFinite()) line.push_back(p);
    gl::DrawLineStrip(line, {.rgb = TrajectoryColor(t.cluster),
                             .width_px = kTrajectoryWidthPx * ss,
                             .dashed = t.dashed,
                             .dash_px = kDashPx * ss});
  }
  gl::DrawLines(FrustumSegments(world_from_cam, cam, o.frustum_depth_m),
                {.rgb = kFrustumRgb, .width_px = kFrustumWidthPx * ss});
  cv::Mat image = context.ReadPixels();
  if (ss > 1) cv::resize(image, image, cv::Size(o.width, o.height), 0, 0, cv::INTER_AREA);

  std::map<int, int> counts;
  for (const auto& p : landmarks) ++counts[std::max(p.cluster, -1)];
  std::vector<LegendEntry> entries;
  for (const auto& [cluster, count] : counts)
    entries.push_back({ClusterName(cluster) + " (" + std::to_string(count) + ")",
                       ColorForCluster(cluster), LegendMarker::kDot});
  for (const auto& t : recent)
    if (!t.label.empty())
      entries.push_back({t.label, TrajectoryColor(t.cluster),
                         t.dashed ? LegendMarker::kDashedLine : LegendMarker::kLine});
  DrawLegend(image, entries, {kLegendMargin, kLegendMargin});
  return image;
}

}  // namespace

void SnapshotOptions::Check() const {
  CheckOption(width > 0, "snapshot.width", "must be > 0", width);
  CheckOption(height > 0, "snapshot.height", "must be > 0", height);
  CheckOption(horizontal_fov_deg > 0 && horizontal_fov_deg < 170, "snapshot.horizontal_fov_deg",
              "must be in (0, 170)", horizontal_fov_deg);
  CheckOption(back_m >= 0, "snapshot.back_m", "must be >= 0", back_m);
  CheckOption(std::isfinite(up_m), "snapshot.up_m", "must be finite", up_m);
  CheckOption(look_ahead_m > 0, "snapshot.look_ahead_m", "must be > 0", look_ahead_m);
  CheckOption(far_m > 1.0, "snapshot.far_m", "must be > 1", far_m);
  CheckOption(landmark_size_px > 0, "snapshot.landmark_size_px", "must be > 0", landmark_size_px);
  CheckOption(dense_point_size_px > 0, "snapshot.dense_point_size_px", "must be > 0",
              dense_point_size_px);
  CheckOption(frustum_depth_m > 0, "snapshot.frustum_depth_m", "must be > 0", frustum_depth_m);
  CheckOption(std::isfinite(ground_below_m), "snapshot.ground_below_m", "must be finite",
              ground_below_m);
  CheckOption(grid_step_m > 0, "snapshot.grid_step_m", "must be > 0", grid_step_m);
  CheckOption(grid_extent_m > 0 && grid_extent_m / grid_step_m <= 1000, "snapshot.grid_extent_m",
              "must be > 0 and at most 1000 grid steps", grid_extent_m);
  CheckOption(supersampling >= 1 && supersampling <= 4, "snapshot.supersampling",
              "must be in 1..4", supersampling);
  dense.Check();
}

void SnapshotOptions::Load(OptionsReader& reader) {
  reader.Read("width", &width);
  reader.Read("height", &height);
  reader.Read("horizontal_fov_deg", &horizontal_fov_deg);
  reader.Read("back_m", &back_m);
  reader.Read("up_m", &up_m);
  reader.Read("look_ahead_m", &look_ahead_m);
  reader.Read("far_m", &far_m);
  reader.Read("landmark_size_px", &landmark_size_px);
  reader.Read("dense_point_size_px", &dense_point_size_px);
  reader.Read("frustum_depth_m", &frustum_depth_m);
  reader.Read("ground_below_m", &ground_below_m);
  reader.Read("grid_step_m", &grid_step_m);
  reader.Read("grid_extent_m", &grid_extent_m);
  reader.Read("supersampling", &supersampling);
  reader.ReadSection("dense", &dense);
}

RenderView SnapshotView(const Pose& world_from_cam, const SnapshotOptions& o) {
  RenderView view;
  const Eigen::Vector3d eye = world_from_cam * Eigen::Vector3d(0.0, -o.up_m, -o.back_m);
  const Eigen::Vector3d target = world_from_cam * Eigen::Vector3d(0.0, 0.0, o.look_ahead_m);
  const Eigen::Vector3d up_world = world_from_cam.linear() * Eigen::Vector3d(0.0, -1.0, 0.0);
  view.view_from_world = LookAt(eye, target, up_world);
  view.width = o.width;
  view.height = o.height;
  view.fx = view.fy = 0.5 * o.width / std::tan(0.5 * o.horizontal_fov_deg * M_PI / 180.0);
  view.cx = 0.5 * (o.width - 1);
  view.cy = 0.5 * (o.height - 1);
  view.near_m = 0.1;
  view.far_m = o.far_m;
  return view;
}

cv::Mat RenderSnapshot(const std::vector<RenderPoint>& points, const Pose& world_from_cam,
                       const StereoCamera& cam, const std::vector<RenderTrajectory>& recent,
                       const SnapshotOptions& options) {
  return Render(points, {}, world_from_cam, cam, recent, options);
}

cv::Mat RenderDenseSnapshot(const std::vector<RenderPoint>& points, const Pose& world_from_cam,
                            const StereoCamera& cam, const std::vector<RenderTrajectory>& recent,
                            const cv::Mat& left, const cv::Mat& right,
                            const SnapshotOptions& options) {
  options.Check();
  DenseCloudStats stats;
  const std::vector<RenderPoint> dense =
      LabelDenseCloud(left, right, cam, world_from_cam, points, options.dense, &stats);
  GetLogger("system")->debug("dense snapshot: {} stereo points, {} after the voxel grid, {} labelled",
                             stats.stereo_points, stats.downsampled_points, stats.labelled_points);
  return Render(points, dense, world_from_cam, cam, recent, options);
}

}  // namespace cslam
