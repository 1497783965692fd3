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

int KeepReportedObjects(MapState* map, const MapStateOptions& options) {
  const std::set<int> reported = ReportedClusters(*map, options);
  std::vector<int> released;
  for (const auto& [id, c] : map->clusters())
    if (!reported.count(id)) released.push_back(id);
  for (int id : released) map->ReleaseCluster(id);
  return static_cast<int>(released.size());
}

}  // namespace cslam

