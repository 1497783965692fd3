#pragma once
// A trajectory as the evaluation sees it: poses with optional timestamps and frame indices.
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// A sequence of world_from_cam poses (or world_from_object for object trajectories).
/// `timestamps` (seconds) and `frames` (frame index of each pose) are each either empty or
/// as long as `poses`; KITTI files give frames, TUM files give timestamps. Evaluation
/// associates two trajectories by frame index when both have frames, else by timestamp.
struct Trajectory {
  std::vector<double> timestamps;
  std::vector<Pose> poses;  ///< world_from_cam
  std::vector<int> frames;  ///< frame index of each pose, increasing

  size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  bool HasTimestamps() const { return !timestamps.empty(); }
  bool HasFrames() const { return !frames.empty(); }
};

}  // namespace cslam
