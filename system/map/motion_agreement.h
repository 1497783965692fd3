#pragma once
// How well two trajectories describe the same rigid body: do `world_from_a` and
// `world_from_b` differ only by a constant body-frame transform a_from_b over the frames
// both have? Used by the map (system/map/map_state.h) to tell one object seen twice from two
// objects that happen to share a few (mislabelled) landmarks.
#include <map>
#include <optional>
#include <vector>

#include "core/rigid.h"

namespace cslam {

struct MotionAgreement {
  int frames = 0;            ///< frames both trajectories have a pose at
  double rms_m = 0;          ///< RMS distance between where the two explain the points (m)
  /// Mean distance from the camera to the points (as b places them) over the shared frames
  /// with a camera pose; 0 without camera poses.
  double mean_range_m = 0;
  /// rms_m / mean_range_m: stereo depth noise grows with range, so far objects' trajectories
  /// disagree by metres while near ones agree to centimetres; infinite without a range.
  double relative_rms() const;
  Pose a_from_b = Pose::Identity();  ///< best constant transform (least squares over the points)
};

/// Compares the trajectories over their shared frames, measured on `points_in_b` (the body's
/// points in b's frame: what matters is how far the body's own points would be misplaced).
/// Fewer than 3 points are padded with points 1 m along the axes from their centroid (the
/// origin if none), so a rotation is still measured. frames == 0 when nothing is shared.
/// With fewer than `min_frames` shared frames only `frames` is filled (the caller's test
/// fails anyway; the map compares every pair of clusters after each window). With more than
/// `max_frames` (> 0) shared frames the fit and the RMS use that many of them, evenly spread
/// from the first to the last: the cost of a comparison then stops growing with the clusters'
/// ages (`frames` still counts them all).
MotionAgreement CompareMotions(const std::map<int, Pose>& world_from_a,
                               const std::map<int, Pose>& world_from_b,
                               const std::vector<Eigen::Vector3d>& points_in_b,
                               const std::vector<std::optional<Pose>>& world_from_cam = {},
                               int min_frames = 1, int max_frames = 0);

/// A trajectory that holds still at the identity at `frames` (the static world seen as a
/// cluster).
std::map<int, Pose> StaticTrajectory(const std::map<int, Pose>& frames);

}  // namespace cslam
