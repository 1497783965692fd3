#pragma once
// The stereo keypoints of the landmarks in moving clusters, kept past the point where the
// online tracklet table forgets them. At the end of a run each object's pose at a frame is
// measured directly from its keypoints then (system/map/object_tracks.h): a far object's
// place from its own keypoints is unbiased, where the windows' estimates of it can be tens of
// metres off (a window whose cluster also held another car's points). Costs memory in
// proportion to the moving landmarks' observations, not to the run.
#include <span>
#include <unordered_map>
#include <vector>

#include "core/tracklet_table.h"

namespace cslam {

class MapState;

/// Observations of moving landmarks by map landmark id, each landmark's in ascending frames.
class ObjectObservations {
 public:
  /// Keeps the observations in `window_table` of the landmarks `map` now places in a moving
  /// cluster; frames already kept are not added twice. `ids` (may be null): the map id of
  /// each of the window's compact landmark ids (TrackletTable::CompactSlice). Landmarks the
  /// map no longer places in a moving cluster are dropped, so what is kept follows the
  /// objects, not everything that ever moved.
  void Keep(const TrackletTable& window_table, const std::vector<int>* ids, const MapState& map);
  /// A landmark's kept observations (landmark field: its map id), ascending frames.
  std::span<const StereoObservation> Of(int landmark) const;
  size_t num_observations() const { return count_; }

 private:
  std::unordered_map<int, std::vector<StereoObservation>> by_landmark_;
  size_t count_ = 0;
};

}  // namespace cslam
