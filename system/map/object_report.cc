#include "system/map/object_report.h"

#include <algorithm>
#include <vector>

namespace cslam {

std::set<int> ReportedClusters(const MapState& map, const MapStateOptions& options) {
  std::set<int> reported;
  for (const auto& [id, c] : map.clusters())
    if (c.num_landmarks >= options.report_min_landmarks &&
        static_cast<int>(c.world_from_cluster.size()) >= options.report_min_frames &&
        !c.world_from_cluster.empty() &&
        c.windows >= std::min(options.report_min_windows,
                              map.WindowsCovering(c.world_from_cluster.begin()->first,
                                                  c.world_from_cluster.rbegin()->first)))
      reported.insert(id);
  return reported;
}

std::set<int> ReportedLandmarks(const MapState& map, const MapStateOptions& options) {
  const std::set<int> reported = ReportedClusters(map, options);
  std::set<int> landmarks;
  for (int l : map.Landmarks())
    if (reported.count(map.ClusterOf(l))) landmarks.insert(l);
  return landmarks;
}

int KeepClustersHolding(MapState* map, const std::set<int>& landmarks) {
  std::set<int> kept;
  for (int l : landmarks) kept.insert(map->ClusterOf(l));
  std::vector<int> released;
  for (const auto& [id, c] : map->clusters())
    if (!kept.count(id)) released.push_back(id);
  for (int id : released) map->ReleaseCluster(id);
  return static_cast<int>(released.size());
}

}  // namespace cslam

