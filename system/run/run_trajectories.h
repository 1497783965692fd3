#pragma once
// The trajectories of a finished run, built once from its map: what the metrics evaluate and
// the output files hold are the same values.
#include <map>
#include <vector>

#include "system/eval/trajectory.h"
#include "system/map/map_state.h"

namespace cslam {

/// The camera's trajectory and each moving cluster's, with timestamps, over the frames the
/// map has a pose at.
struct RunTrajectories {
  Trajectory camera;
  std::map<int, Trajectory> clusters;  ///< moving cluster id → its poses (clusters with any)
};

/// Builds them from `map`; `timestamps` per frame (frames past its end get 0.1 s steps).
RunTrajectories BuildRunTrajectories(const MapState& map, const std::vector<double>& timestamps);

}  // namespace cslam
