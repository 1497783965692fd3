#include "system/run/run_outputs.h"

#include <algorithm>

namespace cslam {

int PlacingPoseIndex(const Trajectory& cluster, int last_frame) {
  if (cluster.empty()) return -1;
  const auto it = std::lower_bound(cluster.frames.begin(), cluster.frames.end(), last_frame);
  if (it != cluster.frames.end() && *it == last_frame)
    return static_cast<int>(it - cluster.frames.begin());
  return static_cast<int>(cluster.size()) - 1;
}

std::map<int, ClusterCentroid> ClusterCentroids(const RunOutputs& outputs) {
  std::map<int, ClusterCentroid> centroids;
  for (const RunLandmark& l : outputs.landmarks) {
    if (l.cluster < 1) continue;
    const auto c = outputs.clusters.find(l.cluster);
    if (c == outputs.clusters.end()) continue;
    const int k = PlacingPoseIndex(c->second, l.last_frame);
    if (k < 0) continue;
    ClusterCentroid& sum = centroids[l.cluster];
    sum.p += c->second.poses[k].inverse() * l.p_world;
    ++sum.landmarks;
  }
  for (auto& [id, c] : centroids) c.p /= c.landmarks;
  return centroids;
}

}  // namespace cslam
