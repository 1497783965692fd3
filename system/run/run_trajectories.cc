#include "system/run/run_trajectories.h"

namespace cslam {

namespace {

double TimestampOf(const std::vector<double>& timestamps, int frame) {
  return frame < static_cast<int>(timestamps.size()) ? timestamps[frame] : 0.1 * frame;
}

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

}  // namespace

RunTrajectories BuildRunTrajectories(const MapState& map, const std::vector<double>& timestamps) {
  RunTrajectories t;
  t.camera = CameraTrajectory(map, timestamps);
  for (const auto& [id, cluster] : map.clusters())
    if (!cluster.world_from_cluster.empty())
      t.clusters[id] = ClusterTrajectory(cluster, timestamps);
  return t;
}

}  // namespace cslam
