#include "system/map/object_report.h"

#include <vector>

namespace cslam {

std::set<int> ReportedClusters(const MapState& map, const MapStateOptions& options) {
  std::set<int> reported;
  for (const auto& [id, c] : map.clusters())
    if (c.num_landmarks >= options.report_min_landmarks &&
        static_cast<int>(c.world_from_cluster.size()) >= options.report_min_frames)
      reported.insert(id);
  return reported;
}

int KeepReportedObjects(MapState* map, const MapStateOptions& options) {
  const std::set<int> reported = ReportedClusters(*map, options);
  std::vector<int> released;
  for (const auto& [id, c] : map->clusters())
    if (!reported.count(id)) released.push_back(id);
  for (int id : released) map->ReleaseCluster(id);
  return static_cast<int>(released.size());
}

}  // namespace cslam

