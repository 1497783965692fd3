#pragma once
// The labelled objects' true world poses, exported beside the estimated ones
// (objects_gt/<id>.txt / .tum, in objects/'s frames and formats) so that `cslam eval` or evo
// can score any object against its truth, and the pictures can draw it. Synthetic sequences:
// the generator's object pose. KITTI raw: the tracklet box's pose (its frame moved to the
// box centre) carried to the world through the ground-truth camera, for the boxes that move.
#include <map>
#include <string>

#include "system/eval/trajectory.h"
#include "system/pipeline/run_input.h"

namespace cslam {

/// One labelled object's truth.
struct GroundTruthObject {
  std::string type;       ///< KITTI: the tracklet's class ("Van"); synthetic: "object"
  Trajectory trajectory;  ///< world_from_object at each labelled frame < frames
  /// KITTI: the box's length, width, height along its x, y, z (its frame at the box centre);
  /// zero where the truth has no box (synthetic).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
};

/// The labelled moving objects of `input` over its first `frames` frames, by ground-truth id
/// (synthetic: the object index >= 1; KITTI raw: the tracklet id, as metrics.json
/// objects.per_object[].gt_object names them). Empty when the input has no object truth.
std::map<int, GroundTruthObject> GroundTruthObjects(const RunInput& input, int frames);

}  // namespace cslam
