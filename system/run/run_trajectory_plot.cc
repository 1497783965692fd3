#include "system/run/run_trajectory_plot.h"

#include <algorithm>
#include <limits>
#include <map>
#include <string>

#include "core/logging.h"
#include "system/draw/cluster_colors.h"
#include "system/render/trajectory_plot.h"

namespace cslam {

namespace {

// A position that breaks a plotted line (RenderTrajectory::positions).
const Eigen::Vector3d kLineBreak =
    Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());

}  // namespace

RenderTrajectory CameraPathLine(const Trajectory& camera, RenderTrajectory line, int first_frame,
                                int last_frame) {
  for (size_t k = 0; k < camera.size(); ++k) {
    const int f = camera.HasFrames() ? camera.frames[k] : static_cast<int>(k);
    if (f < first_frame || f > last_frame) continue;
    if (!line.positions.empty() && camera.HasFrames() && k > 0 && f > camera.frames[k - 1] + 1)
      line.positions.push_back(kLineBreak);  // tracking lost: no path was estimated there
    line.positions.push_back(camera.poses[k].translation());
  }
  return line;
}

std::vector<RenderTrajectory> ClusterTrackLines(const RunOutputs& outputs,
                                                const TrajectoryPlotOptions& options,
                                                const std::string& picture, int* too_small) {
  // Clusters are plotted when they stay within this distance of the camera's start: the
  // camera's own extent plus a margin for objects seen far ahead.
  const Trajectory& camera = outputs.camera;
  const Eigen::Vector3d start = camera.empty()
                                    ? Eigen::Vector3d::Zero()
                                    : Eigen::Vector3d(camera.poses.front().translation());
  double plot_radius_m = 100.0;
  for (const Pose& p : camera.poses)
    if (p.translation().allFinite())
      plot_radius_m = std::max(plot_radius_m, (p.translation() - start).norm() + 100.0);
  // Each cluster is drawn through its landmarks' centroid rather than its frame origin.
  const std::map<int, ClusterCentroid> centroids = ClusterCentroids(outputs);
  auto log = GetLogger("system");
  // Biggest first, so the legend names the objects before the fragments.
  std::vector<std::pair<int, int>> order;  // (landmarks, id)
  *too_small = 0;
  for (const auto& [id, c] : outputs.clusters) {
    const auto it = centroids.find(id);
    const int n = it == centroids.end() ? 0 : it->second.landmarks;
    if (c.size() < 2) continue;
    if (static_cast<int>(c.size()) < options.min_poses || n < options.min_landmarks) {
      ++*too_small;
      continue;
    }
    order.emplace_back(n, id);
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<RenderTrajectory> lines;
  for (const auto& [n, id] : order) {
    const Trajectory& c = outputs.clusters.at(id);
    // The landmark count and frame span tell an object (hundreds of points, many frames)
    // from a fragment at a glance; the palette repeats every ten clusters.
    RenderTrajectory t{"object " + std::to_string(id) + " (" + std::to_string(n) +
                           " points, frames " + std::to_string(c.frames.front()) + "-" +
                           std::to_string(c.frames.back()) + ")",
                       {}, id, false};
    const Eigen::Vector3d centroid = n > 0 ? centroids.at(id).p : Eigen::Vector3d::Zero();
    // A diverged cluster (kilometres away) would shrink everything else to a dot; leave it
    // out of the plot and say so (its trajectory file is still written).
    bool diverged = false;
    for (size_t k = 0; k < c.poses.size(); ++k) {
      const Eigen::Vector3d p = c.poses[k] * centroid;
      diverged |= !p.allFinite() || (p - start).norm() > plot_radius_m;
      // No line across frames without a pose: the object was out of sight there (behind
      // another, or lost), and a straight segment would show a path nobody saw.
      if (k > 0 && c.HasFrames() && c.frames[k] > c.frames[k - 1] + 1)
        t.positions.push_back(kLineBreak);
      t.positions.push_back(p);
    }
    if (diverged) {
      log->warn("{}: cluster {} left out, it strays more than {:.0f} m from the camera's path",
                picture, id, plot_radius_m);
      continue;
    }
    lines.push_back(t);
  }
  return lines;
}

std::vector<RenderTrajectory> RunTrajectoryPlotLines(const RunOutputs& outputs,
                                                     const TrajectoryPlotOptions& options) {
  std::vector<RenderTrajectory> trajs;
  if (!outputs.gt_camera.empty()) {
    RenderTrajectory gt{"camera (ground truth)", {}, -1, true};
    for (const Pose& p : outputs.gt_camera.poses) gt.positions.push_back(p.translation());
    trajs.push_back(gt);
  }
  for (const auto& [id, t] : outputs.gt_objects)
    if (t.size() >= 2) trajs.push_back(GroundTruthObjectLine(outputs, id, t.frames.back()));
  trajs.push_back(CameraPathLine(outputs.camera, {"camera", {}, -1, false}));
  int too_small = 0;
  for (RenderTrajectory& t :
       ClusterTrackLines(outputs, options, "render/trajectory.png", &too_small))
    trajs.push_back(std::move(t));
  if (too_small > 0)
    trajs.push_back({"+ " + std::to_string(too_small) + " small clusters not drawn (< " +
                         std::to_string(options.min_landmarks) + " points or < " +
                         std::to_string(options.min_poses) + " poses)",
                     {}, kUndrawnClusters, false});
  return trajs;
}

cv::Mat RenderRunTrajectoryPlot(const RunOutputs& outputs, int width, int height,
                                const TrajectoryPlotOptions& options) {
  return RenderTrajectoryTopView(RunTrajectoryPlotLines(outputs, options), width, height);
}

}  // namespace cslam
