#pragma once
// The map's prior for an online backend window (backend/window_prior.h): what the windows
// integrated so far settled about its frames and landmarks, in the window's own frame.
#include <optional>
#include <vector>

#include "backend/window_prior.h"
#include "core/tracklet_table.h"
#include "system/map/map_state.h"

namespace cslam {

/// The prior of a window over `range` whose observations are `table`: every landmark observed
/// in the range gets its map cluster (or -1), static ones their map position, and every frame
/// the map has a camera pose for gets it, all mapped into the window's world frame (the camera
/// at range.begin). nullopt when the map has no camera pose at range.begin (the first window,
/// or the first after a tracking break): there is nothing to express the prior in.
/// `ids` (may be null): the map's landmark id of each of `table`'s (TrackletTable::CompactSlice).
std::optional<WindowPrior> WindowPriorFromMap(const MapState& map, const TrackletTable& table,
                                              FrameRange range,
                                              const std::vector<int>* ids = nullptr);

}  // namespace cslam
