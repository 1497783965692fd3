#pragma once
// An object's error as the camera sees it: the estimated object against the ground truth, each
// in its own camera frame, so neither the camera's drift nor the ground truth's world (on KITTI,
// GPS positions good to a few decimetres) enters the figure.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// One frame of an object: the estimate's reference point in the estimate's camera frame, and
/// the ground-truth object pose in the ground-truth camera frame of the same frame.
struct ObjectInCamera {
  Eigen::Vector3d est_point_in_cam = Eigen::Vector3d::Zero();
  Pose gt_cam_from_object = Pose::Identity();
};

/// The RMS distance between the estimated point and where it lies on the true object, and that
/// place in the object's frame.
struct ObjectCameraFrameError {
  double rmse_m = NAN;  ///< NaN with fewer than 3 frames
  Eigen::Vector3d point_in_object = Eigen::Vector3d::Zero();
  int frames = 0;
};

/// With `fit_point`, the estimate's reference point is a fixed but unknown point of the object
/// (the centroid of the landmarks a camera saw on it, not a box's centre): its place in the
/// object frame is the least-squares one over the frames, as an ATE's alignment takes out an
/// arbitrary origin. Without it the point is the object frame's origin.
ObjectCameraFrameError ObjectErrorInCameraFrame(const std::vector<ObjectInCamera>& frames,
                                                bool fit_point);

}  // namespace cslam
