#include "system/map/object_observations.h"

#include "system/map/map_state.h"

namespace cslam {

void ObjectObservations::Keep(const TrackletTable& window_table, const std::vector<int>* ids,
                              const MapState& map) {
  for (auto it = by_landmark_.begin(); it != by_landmark_.end();) {
    if (map.ClusterOf(it->first) >= 1) {
      ++it;
      continue;
    }
    count_ -= it->second.size();
    it = by_landmark_.erase(it);
  }
  for (int l = 0; l < window_table.num_landmarks(); ++l) {
    const int id = ids ? (*ids)[l] : l;
    if (map.ClusterOf(id) < 1) continue;
    std::vector<StereoObservation>& kept = by_landmark_[id];
    for (StereoObservation o : window_table.ObservationsOf(l)) {
      if (!kept.empty() && o.frame <= kept.back().frame) continue;
      o.landmark = id;
      kept.push_back(o);
      ++count_;
    }
  }
}

std::span<const StereoObservation> ObjectObservations::Of(int landmark) const {
  const auto it = by_landmark_.find(landmark);
  if (it == by_landmark_.end()) return {};
  return it->second;
}

}  // namespace cslam
