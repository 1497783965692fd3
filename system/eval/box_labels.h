#pragma once
// Ground-truth landmark labels from labelled 3-D boxes (KITTI raw tracklets): a landmark
// belongs to a moving object when, in most of its observations, its keypoint falls inside the
// box's outline in the image and its stereo depth lies within the box's depth range, each up to
// its own uncertainty. A box in 3-D with a fixed margin refused a far object's points: at 80 m each
// point's depth is metres off, so none fell inside and a correct object counted as a false one.
// Parked vehicles are boxes too, but they do not move: their landmarks stay static (label 0),
// as the clustering should leave them.
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "system/datasets/stereo_source.h"

namespace cslam {

/// Options of the box-based labelling.
struct BoxLabelOptions {
  /// An observation's keypoint and depth may lie this many of their own standard deviations
  /// (from its keypoint covariance) outside the box's outline and depth range (3: 99.7 % of a
  /// normal error).
  double depth_sigmas = 3.0;
  double min_inside_fraction = 0.5; ///< of a landmark's observations, to take the label
  double min_travel_m = 3.0;        ///< an object moving less than this in the world is static
};

/// Track ids of the boxes that move in the world by more than min_travel_m over their life.
/// `world_from_cam` is the ground-truth camera trajectory (boxes are per-frame camera-relative).
std::vector<int> MovingTrackIds(const std::vector<std::vector<ObjectBox>>& boxes,
                                const std::vector<Pose>& world_from_cam,
                                const BoxLabelOptions& options = {});

/// Per landmark of `table`: 1 + the index in `moving_tracks` of the moving object it lies on,
/// 0 otherwise (static or unlabelled).
std::vector<int> LabelLandmarksByBoxes(const TrackletTable& table, const StereoCamera& camera,
                                       const std::vector<std::vector<ObjectBox>>& boxes,
                                       const std::vector<int>& moving_tracks,
                                       const BoxLabelOptions& options = {});

/// World trajectory of a box's centre (the bottom-face origin raised by h/2) for the frames
/// where the box is labelled: (frame, world position).
std::vector<std::pair<int, Eigen::Vector3d>> BoxCentreTrajectory(
    const std::vector<std::vector<ObjectBox>>& boxes, const std::vector<Pose>& world_from_cam,
    int track_id);

}  // namespace cslam
