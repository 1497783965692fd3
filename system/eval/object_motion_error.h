#pragma once
// An object's frame-to-frame motion error (ME_r, ME_t), as the dynamic-SLAM literature reports
// it (VDO-SLAM, DynoSAM): the error of the object's rigid motion between consecutive frames,
// which does not depend on where the object's body frame sits. Each motion is taken in its own
// camera frame at the earlier frame, so neither the camera's drift nor the world's origin
// enters, and its translation error is measured at the object's true centre, where a wrong
// rotation misplaces the object by what it really does.
#include <optional>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// One frame of an object: the estimated object and camera poses in the estimate's world, the
/// true ones in the ground truth's world.
struct ObjectFramePoses {
  int frame = 0;
  Pose est_world_from_object = Pose::Identity();
  Pose est_world_from_cam = Pose::Identity();
  Pose gt_world_from_object = Pose::Identity();
  Pose gt_world_from_cam = Pose::Identity();
};

/// Means over the pairs of consecutive frames (frame and frame + 1 both present).
struct ObjectMotionError {
  double me_r_deg = 0;  ///< mean rotation error of the per-frame motion, degrees
  double me_t_m = 0;    ///< mean translation error at the object's true centre, metres
  double max_r_deg = 0; ///< the largest per-pair rotation error, degrees
  int pairs = 0;        ///< 0: no consecutive frames, the means are meaningless
};

/// `frames` ascending by frame.
ObjectMotionError ComputeObjectMotionError(const std::vector<ObjectFramePoses>& frames);

/// The largest turn of a trajectory between consecutive frames, and the later frame.
struct FrameToFrameRotation {
  double deg = 0;
  int frame = -1;
};

/// The rotation of the world motion between consecutive poses of one trajectory: how far it
/// turned from one frame to the next, whatever its body frame. Needs no ground truth.
/// `frames` and `world_from_object` run in parallel, ascending; only pairs of consecutive
/// frames count. Empty when there is none.
std::optional<FrameToFrameRotation> LargestFrameToFrameRotation(
    const std::vector<int>& frames, const std::vector<Pose>& world_from_object);

}  // namespace cslam
