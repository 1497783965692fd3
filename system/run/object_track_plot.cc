#include "system/run/object_track_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/errors.h"
#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"
#include "system/io/image_io.h"
#include "system/render/trajectory_plot.h"
#include "system/run/run_trajectory_plot.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// Every reported object is drawn, however small: the picture is about the objects.
constexpr TrajectoryPlotOptions kEveryObject{.min_poses = 2, .min_landmarks = 0};
// The legend names at most this many labelled objects not found, then counts the rest.
constexpr size_t kMaxNamedMissed = 6;
// px right of and above a track's start where its id is written.
constexpr int kIdOffsetPx = 6;

std::string Fixed(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// "object 3, frames 10-80", then its motion error, or why there is none. `truth` is the
// labelled object matched to it (-1: none).
std::string ObjectLabel(const RunOutputs& outputs, int id, const RunMetrics::PerObject* errors,
                        int truth, bool labelled_run) {
  const Trajectory& t = outputs.clusters.at(id);
  std::string label = "object " + std::to_string(id);
  // The class of the labelled object matched to it (KITTI's "Van"); synthetic ones have none.
  const auto match = outputs.gt_object_match.find(truth);
  if (match != outputs.gt_object_match.end() && match->second.first != "object")
    label += " (" + match->second.first + ")";
  label += ", frames " + std::to_string(t.frames.front()) + "-" + std::to_string(t.frames.back());
  if (errors && errors->me_r_deg && errors->me_t_m)
    return label + ": ME_r " + Fixed(*errors->me_r_deg, 2) + " deg, ME_t " +
           Fixed(*errors->me_t_m, 3) + " m";
  if (truth >= 0) return label + ": truth id " + std::to_string(truth) + ", no motion error";
  return labelled_run ? label + ": no labelled object matched" : label;
}

}  // namespace

std::vector<RenderTrajectory> ObjectTrackPlotLines(const RunOutputs& outputs,
                                                   const RunMetrics* metrics) {
  // The matching: metrics.json's when there is one (it carries the errors), else
  // objects_gt/index.csv's (a run scored without metrics, or an older folder).
  std::map<int, const RunMetrics::PerObject*> errors;  // by cluster
  std::map<int, int> truth_of;                         // cluster -> ground-truth id
  if (metrics)
    for (const RunMetrics::PerObject& po : metrics->objects.per_object)
      if (po.cluster && *po.cluster >= 1) {
        errors[*po.cluster] = &po;
        truth_of[*po.cluster] = po.gt_object;
      }
  for (const auto& [gt, match] : outputs.gt_object_match)
    if (match.second >= 1) truth_of.emplace(match.second, gt);
  const bool labelled_run =
      !outputs.gt_objects.empty() || (metrics && !metrics->objects.per_object.empty());

  int too_small = 0;
  std::vector<RenderTrajectory> tracks =
      ClusterTrackLines(outputs, kEveryObject, "render/objects.png", &too_small);
  std::sort(tracks.begin(), tracks.end(), [](const RenderTrajectory& a, const RenderTrajectory& b) {
    return a.cluster < b.cluster;
  });
  int first = std::numeric_limits<int>::max(), last = std::numeric_limits<int>::min();
  for (RenderTrajectory& t : tracks) {
    const Trajectory& c = outputs.clusters.at(t.cluster);
    first = std::min(first, c.frames.front());
    last = std::max(last, c.frames.back());
    const auto e = errors.find(t.cluster);
    const auto truth = truth_of.find(t.cluster);
    t.label = ObjectLabel(outputs, t.cluster, e == errors.end() ? nullptr : e->second,
                          truth == truth_of.end() ? -1 : truth->second, labelled_run);
  }

  std::vector<RenderTrajectory> lines;
  // The camera only over the objects' frames: the whole drive would shrink them to dots.
  const bool any = !tracks.empty();
  if (!any && !outputs.camera.frames.empty()) {
    first = outputs.camera.frames.front();
    last = outputs.camera.frames.back();
  }
  RenderTrajectory camera =
      CameraPathLine(outputs.camera, {"", {}, kContextPath, false}, first, last);
  if (!camera.positions.empty())
    camera.label = "camera, frames " + std::to_string(first) + "-" + std::to_string(last);
  lines.push_back(std::move(camera));
  lines.insert(lines.end(), tracks.begin(), tracks.end());
  if (!any) lines.push_back({"no object reported", {}, kUndrawnClusters, false});
  const size_t not_drawn = outputs.clusters.size() - tracks.size();
  if (any && not_drawn > 0)
    lines.push_back({"+ " + std::to_string(not_drawn) +
                         " objects not drawn (one pose, or far off the camera's path)",
                     {},
                     kUndrawnClusters,
                     false});

  // The truth of each drawn object over the frames it was tracked, where a reader compares it.
  bool dashed = false;
  for (const RenderTrajectory& t : tracks) {
    const auto gt = truth_of.find(t.cluster);
    if (gt == truth_of.end() || !outputs.gt_objects.count(gt->second)) continue;
    const Trajectory& c = outputs.clusters.at(t.cluster);
    RenderTrajectory truth =
        GroundTruthObjectLine(outputs, gt->second, c.frames.back(), c.frames.front());
    truth.label.clear();  // one legend row names every dashed line
    truth.cluster = t.cluster;
    if (truth.positions.size() < 2) continue;
    lines.push_back(std::move(truth));
    dashed = true;
  }
  if (dashed)
    lines.push_back(
        {"ground truth over the same frames (dashed, in its object's colour)", {}, -1, true});
  std::vector<int> missed;
  for (const auto& [gt, t] : outputs.gt_objects) {
    const auto match = outputs.gt_object_match.find(gt);
    if (match == outputs.gt_object_match.end() || match->second.second < 1) missed.push_back(gt);
  }
  if (!missed.empty()) {
    std::string ids;
    for (size_t k = 0; k < missed.size() && k < kMaxNamedMissed; ++k)
      ids += (k ? ", " : "") + std::to_string(missed[k]);
    if (missed.size() > kMaxNamedMissed) ids += ", ...";
    lines.push_back({std::to_string(missed.size()) +
                         (missed.size() == 1 ? " labelled object" : " labelled objects") +
                         " not found (truth id " + ids + ")",
                     {},
                     kUndrawnClusters,
                     true});
  }
  return lines;
}

cv::Mat RenderObjectTrackPlot(const RunOutputs& outputs, const RunMetrics* metrics, int width,
                              int height) {
  const std::vector<RenderTrajectory> lines = ObjectTrackPlotLines(outputs, metrics);
  cv::Mat image = RenderTrajectoryTopView(
      lines, width, height, "Object tracks, top view (x-z plane of the first camera frame)");
  // Each object's id beside the dot where its track starts: where tracks crowd (a junction),
  // colours alone do not tell ten objects apart.
  const TopViewLayout layout = ComputeTopViewLayout(lines, width, height);
  const cv::Rect plot(layout.plot_left, layout.plot_top, layout.plot_right - layout.plot_left,
                      layout.plot_bottom - layout.plot_top);
  for (const RenderTrajectory& t : lines) {
    if (t.dashed || t.cluster < 1) continue;
    const auto start = std::find_if(t.positions.begin(), t.positions.end(),
                                    [](const Eigen::Vector3d& p) { return p.allFinite(); });
    if (start == t.positions.end()) continue;
    const Eigen::Vector2d px = layout.ToPixel(*start);
    const cv::Point at(static_cast<int>(std::lround(px.x())) + kIdOffsetPx,
                       static_cast<int>(std::lround(px.y())) - kIdOffsetPx);
    if (!plot.contains(at) || layout.legend.contains(at)) continue;
    PutLabel(image, std::to_string(t.cluster), at, TextAlign::kLeft, 0.5,
             TrajectoryColor(t.cluster));
  }
  return image;
}

std::string WriteObjectTrackPlot(const RunOutputs& outputs, const std::string& out_dir, int width,
                                 int height) {
  const fs::path metrics_file = fs::path(out_dir) / "metrics.json";
  std::optional<RunMetrics> metrics;
  std::error_code ec;
  if (fs::exists(metrics_file, ec)) {
    std::ifstream in(metrics_file);
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded()) throw InputError(metrics_file.string(), "not valid JSON");
    metrics = RunMetricsFromJson(j, metrics_file.string());
  }
  const std::string path = (fs::path(out_dir) / "render" / "objects.png").string();
  WritePng(RenderObjectTrackPlot(outputs, metrics ? &*metrics : nullptr, width, height), path);
  return path;
}

}  // namespace cslam
