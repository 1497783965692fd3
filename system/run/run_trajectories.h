#pragma once
// A finished run's trajectories, built once from its map: the metrics evaluate them and the
// writer writes them, so both see the very same poses and timestamps.
#include <map>
#include <vector>

#include "system/eval/trajectory.h"
#include "system/map/map_state.h"

namespace cslam {

/// The camera's and every moving cluster's trajectory of a map; each pose carries its frame
/// index and timestamp (seconds).
struct RunTrajectories {
  Trajectory camera;                   ///< the frames with a camera pose
  std::map<int, Trajectory> clusters;  ///< by cluster id, every map cluster with a pose
};

/// The trajectories of `map`, timestamped from `timestamps` (frame index → seconds; frames
/// past its end get 0.1 s per frame).
RunTrajectories BuildRunTrajectories(const MapState& map, const std::vector<double>& timestamps);

}  // namespace cslam
