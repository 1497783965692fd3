#include "system/map/window_prior.h"

#include <limits>

namespace cslam {

std::optional<WindowPrior> WindowPriorFromMap(const MapState& map, const TrackletTable& table,
                                              FrameRange range, const std::vector<int>* ids) {
  const auto& poses = map.world_from_cam();
  if (range.size() <= 0 || range.begin >= map.num_frames() || !poses[range.begin])
    return std::nullopt;
  const Pose window_from_map = poses[range.begin]->inverse();
  WindowPrior prior;
  prior.range = range;
  prior.world_from_cam.resize(range.size());
  for (int f = range.begin; f < range.end && f < map.num_frames(); ++f)
    if (poses[f]) prior.world_from_cam[f - range.begin] = window_from_map * *poses[f];
  prior.world_from_cam[0] = Pose::Identity();  // exactly, not up to rounding
  const int n = table.num_landmarks();
  prior.landmark_cluster.assign(n, -1);
  prior.static_point.assign(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (int l : table.LandmarksIn(range)) {
    const int id = ids ? (*ids)[l] : l;
    const int cluster = map.ClusterOf(id);
    prior.landmark_cluster[l] = cluster;
    if (cluster != 0) continue;
    if (const auto p = map.PositionInCluster(id)) prior.static_point[l] = window_from_map * *p;
  }
  return prior;
}

}  // namespace cslam
