#pragma once
// A moving cluster's final trajectory holds only the poses its own landmarks observe. A window
// places a cluster at every frame of its span, also where its landmarks of that window were
// then few or, after later windows gave some of them to another cluster, none; and the shape
// initialisation carries a pose over frames with fewer than three points. Such a pose is not
// an observation of the body: on KITTI raw 0005 played backwards, the van's cluster had 20 such
// frames, held by 2 background points, and they were 3 m off.
#include "core/tracklet_table.h"
#include "system/map/map_state.h"

namespace cslam {

/// What KeepSupportedPoses changed.
struct SupportedPoses {
  int dropped = 0;   ///< poses removed
  int released = 0;  ///< clusters with no supported pose left, released (ReleaseCluster)
};

/// Removes each moving cluster's poses at frames where fewer than `min_points` of its
/// landmarks are seen (a rigid body's pose needs three points; `table`'s spans, tracks being
/// contiguous); a cluster left with none is released, its landmarks outliers.
SupportedPoses KeepSupportedPoses(MapState* map, const TrackletTable& table, int min_points);

}  // namespace cslam
