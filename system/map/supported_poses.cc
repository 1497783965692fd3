#include "system/map/supported_poses.h"

#include <map>
#include <vector>

namespace cslam {

SupportedPoses KeepSupportedPoses(MapState* map, const TrackletTable& table, int min_points) {
  // Per cluster, +1 at a landmark's first frame and -1 after its last: a running sum gives the
  // landmarks seen at each frame.
  std::map<int, std::map<int, int>> steps;
  for (int l : map->Landmarks()) {
    const int cluster = map->ClusterOf(l);
    if (cluster < 1 || l >= table.num_landmarks()) continue;
    const LandmarkSpan& span = table.Span(l);
    if (span.first_frame < 0) continue;
    ++steps[cluster][span.first_frame];
    --steps[cluster][span.last_frame + 1];
  }
  SupportedPoses out;
  std::vector<int> unsupported_clusters;
  for (const auto& [id, cluster] : map->clusters()) {
    if (id < 1) continue;
    const auto s = steps.find(id);
    if (s == steps.end()) {  // none of its landmarks is tracked
      unsupported_clusters.push_back(id);
      continue;
    }
    std::vector<int> drop;
    auto step = s->second.cbegin();
    int seen = 0;
    for (const auto& [frame, pose] : cluster.world_from_cluster) {
      for (; step != s->second.cend() && step->first <= frame; ++step) seen += step->second;
      if (seen < min_points) drop.push_back(frame);
    }
    if (drop.size() == cluster.world_from_cluster.size()) {
      unsupported_clusters.push_back(id);
      continue;
    }
    for (int f : drop) map->ErasePose(id, f);
    out.dropped += static_cast<int>(drop.size());
  }
  for (int id : unsupported_clusters) map->ReleaseCluster(id);
  out.released = static_cast<int>(unsupported_clusters.size());
  return out;
}

}  // namespace cslam
