#include "system/run_writer.h"

#include <filesystem>
#include <iomanip>
#include <map>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/logging.h"
#include "system/image_io.h"
#include "system/point_cloud_export.h"
#include "system/render_scene.h"
#include "system/trajectory_io.h"
#include "system/trajectory_plot.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

double TimestampOf(const std::vector<double>& timestamps, int frame) {
  return frame < static_cast<int>(timestamps.size()) ? timestamps[frame] : 0.1 * frame;
}

// The frame each landmark was last observed in (where its world position is reported).
int LastFrameOf(const TrackletTable& table, int landmark) {
  return landmark < table.num_landmarks() ? table.Span(landmark).last_frame : -1;
}

int FirstFrameOf(const TrackletTable& table, int landmark) {
  return landmark < table.num_landmarks() ? table.Span(landmark).first_frame : -1;
}

}  // namespace

Trajectory CameraTrajectory(const MapState& map, const std::vector<double>& timestamps) {
  Trajectory t;
  for (int f = 0; f < map.num_frames(); ++f) {
    if (!map.world_from_cam()[f]) continue;
    t.frames.push_back(f);
    t.timestamps.push_back(TimestampOf(timestamps, f));
    t.poses.push_back(*map.world_from_cam()[f]);
  }
  return t;
}

Trajectory ClusterTrajectory(const MapCluster& cluster, const std::vector<double>& timestamps) {
  Trajectory t;
  for (const auto& [f, pose] : cluster.world_from_cluster) {
    t.frames.push_back(f);
    t.timestamps.push_back(TimestampOf(timestamps, f));
    t.poses.push_back(pose);
  }
  return t;
}

void WriteRunOutputs(const RunInput& input, const PipelineResult& result,
                     const PipelineOptions& options, const std::string& out_dir,
                     const RunMetrics* metrics) {
  auto log = GetLogger("system");
  const fs::path out(out_dir);
  const MapState& map = result.map;

  const Trajectory camera = CameraTrajectory(map, input.timestamps);
  WriteTrajectory(camera, (out / "camera_trajectory.txt").string(), TrajectoryFormat::kKitti);
  WriteTrajectory(camera, (out / "camera_trajectory.tum").string(), TrajectoryFormat::kTum);
  // KITTI files carry no frame numbers: say which frames the lines are when any is missing.
  if (static_cast<int>(camera.frames.size()) != result.frames_processed || !map.gaps().empty()) {
    WriteFileAtomically((out / "camera_trajectory_frames.txt").string(), [&](std::ostream& o) {
      o << "# frame index of each line of camera_trajectory.txt\n";
      for (int f : camera.frames) o << f << "\n";
      for (int g : map.gaps()) o << "# gap: trajectory chained without overlap at frame " << g << "\n";
    });
  }

  WriteFileAtomically((out / "objects" / "index.csv").string(), [&](std::ostream& o) {
    o << "cluster,first_frame,last_frame,frames,landmarks\n";
    for (const auto& [id, c] : map.clusters()) {
      if (c.world_from_cluster.empty()) continue;
      o << id << "," << c.world_from_cluster.begin()->first << ","
        << c.world_from_cluster.rbegin()->first << "," << c.world_from_cluster.size() << ","
        << c.num_landmarks << "\n";
    }
  });
  for (const auto& [id, c] : map.clusters()) {
    if (c.world_from_cluster.empty()) continue;
    const Trajectory t = ClusterTrajectory(c, input.timestamps);
    const std::string stem = (out / "objects" / std::to_string(id)).string();
    WriteTrajectory(t, stem + ".txt", TrajectoryFormat::kKitti);
    WriteTrajectory(t, stem + ".tum", TrajectoryFormat::kTum);
    WriteFileAtomically(stem + "_frames.txt", [&](std::ostream& o) {
      for (int f : t.frames) o << f << "\n";
    });
  }

  std::vector<RenderPoint> cloud;
  WriteFileAtomically((out / "clusters.csv").string(), [&](std::ostream& o) {
    o << "landmark,cluster,first_frame,last_frame,x,y,z\n";
    o << std::setprecision(9);
    for (int l : map.Landmarks()) {
      const int last = LastFrameOf(result.table, l);
      const int cluster = map.ClusterOf(l);
      // Moving landmarks are placed where their cluster was when they were last seen (or at
      // the cluster's last pose when it has none for that frame).
      std::optional<Eigen::Vector3d> p = map.WorldPosition(l, last);
      if (!p && cluster >= 1) {
        const auto it = map.clusters().find(cluster);
        if (it != map.clusters().end() && !it->second.world_from_cluster.empty())
          p = it->second.world_from_cluster.rbegin()->second * *map.PositionInCluster(l);
      }
      if (!p) continue;
      o << l << "," << cluster << "," << FirstFrameOf(result.table, l) << "," << last << ","
        << p->x() << "," << p->y() << "," << p->z() << "\n";
      cloud.push_back({*p, cluster});
    }
  });
  WriteLandmarkClouds(cloud, (out / "landmarks.ply").string(), (out / "landmarks.pcd").string());

  WriteFileAtomically((out / "config.yaml").string(),
                      [&](std::ostream& o) { o << options.ToYaml(); });

  if (options.output.trajectory_plot) {
    std::vector<RenderTrajectory> trajs;
    if (input.gt_world_from_cam) {
      RenderTrajectory gt{"camera (ground truth)", {}, -1, true};
      for (int f : camera.frames)
        if (f < static_cast<int>(input.gt_world_from_cam->size()))
          gt.positions.push_back((*input.gt_world_from_cam)[f].translation());
      trajs.push_back(gt);
    }
    RenderTrajectory cam{"camera", {}, -1, false};
    for (const Pose& p : camera.poses) cam.positions.push_back(p.translation());
    trajs.push_back(cam);
    // Clusters are plotted when they stay within this distance of the camera's start: the
    // camera's own extent plus a margin for objects seen far ahead.
    const Eigen::Vector3d start =
        cam.positions.empty() ? Eigen::Vector3d::Zero() : cam.positions.front();
    double plot_radius_m = 100.0;
    for (const auto& p : cam.positions)
      plot_radius_m = std::max(plot_radius_m, (p - start).norm() + 100.0);
    // Draw each cluster's landmark centroid rather than its frame origin, which can lie
    // anywhere (it is the camera frame at the cluster's first sighting). One pass over the
    // landmarks gathers every cluster's centroid.
    std::map<int, std::pair<Eigen::Vector3d, int>> centroids;
    for (int l : map.Landmarks()) {
      const int id = map.ClusterOf(l);
      if (id < 1) continue;
      auto& [sum, n] = centroids.try_emplace(id, Eigen::Vector3d::Zero(), 0).first->second;
      sum += *map.PositionInCluster(l);
      ++n;
    }
    for (const auto& [id, c] : map.clusters()) {
      if (c.world_from_cluster.size() < 2) continue;
      RenderTrajectory t{"cluster " + std::to_string(id), {}, id, false};
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      if (const auto it = centroids.find(id); it != centroids.end() && it->second.second > 0)
        centroid = it->second.first / it->second.second;
      for (const auto& [f, pose] : c.world_from_cluster) t.positions.push_back(pose * centroid);
      // A diverged cluster (kilometres away) would shrink everything else to a dot; leave it
      // out of the plot and say so (its trajectory file is still written).
      bool diverged = false;
      for (const auto& p : t.positions)
        diverged |= !p.allFinite() || (p - start).norm() > plot_radius_m;
      if (diverged) {
        log->warn("render/trajectory.png: cluster {} left out, it strays more than {:.0f} m from "
                  "the camera's path",
                  id, plot_radius_m);
        continue;
      }
      trajs.push_back(t);
    }
    try {
      WritePng(RenderTrajectoryTopView(trajs), (out / "render" / "trajectory.png").string());
    } catch (const OutputError&) {
      throw;
    } catch (const Error& e) {
      log->warn("render/trajectory.png not written: {}", e.what());
    }
  }

  WriteResourceLog(result.resources, out_dir, options.output.trajectory_plot);
  if (metrics) WriteMetricsJson(*metrics, (out / "metrics.json").string());
}

}  // namespace cslam
