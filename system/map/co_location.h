#pragma once
// Do two moving clusters occupy the same space at the same time? Two rigid bodies cannot, so
// two map clusters that do are pieces of one object that the windows cut apart: the legs and
// the frame of a cyclist, or the same body found again by a later window from new tracks.
// The map (system/map/map_state.h) merges such pieces next to those whose motions agree as one
// rigid body; that test asks for agreement within the depth noise and so never joins the
// parts of a body that is not rigid.
#include <map>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// Where two clusters' points lie over the frames both have a pose at.
struct CoLocation {
  int frames = 0;  ///< shared frames
  /// Median over the shared frames of the distance between the two clusters' centroids
  /// divided by the smaller of their RMS radii (a cluster's points about its centroid):
  /// ≤ 1 means that in most shared frames each centre lay inside the other body's extent.
  double median_ratio = 0;
};

/// Compares where `world_from_a` places `points_in_a` with where `world_from_b` places
/// `points_in_b`, frame by frame. frames == 0 when nothing is shared or a side has no point.
CoLocation CompareLocations(const std::map<int, Pose>& world_from_a,
                            const std::vector<Eigen::Vector3d>& points_in_a,
                            const std::map<int, Pose>& world_from_b,
                            const std::vector<Eigen::Vector3d>& points_in_b);

}  // namespace cslam
