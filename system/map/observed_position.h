#pragma once
// A body's pose at one frame measured from its own keypoints then. Its landmarks' places in
// the body frame are known at the end of a run (from the windows that saw it near); the
// keypoints of one frame then fix where the body is and, less well, how it is turned. Solved
// on the keypoints themselves (stereo reprojection, each with its covariance) rather than on
// triangulated points, whose depth at range is biased and heavy-tailed.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/rigid.h"
#include "core/stereo_camera.h"

namespace cslam {

/// One landmark seen at the frame: its position in the body frame and its stereo keypoint
/// (uL, vL, uR) with its covariance (px²).
struct BodyKeypoint {
  Eigen::Vector3d in_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
};

/// The body's pose the keypoints give and how many of them agree with it.
struct ObservedPose {
  Pose world_from_body = Pose::Identity();
  int inliers = 0;  ///< keypoints within the χ²₃ 99.9 % gate of their projection
  double scale = 1;  ///< of the landmarks' places in the body that fits the keypoints
  /// Covariance of the position (m², world) from the inliers' keypoints.
  Eigen::Matrix3d position_cov = Eigen::Matrix3d::Identity();
};

/// The body pose that best explains `keypoints` with the camera at `world_from_cam`:
/// Levenberg–Marquardt on the whitened stereo reprojection error (rotation perturbed on the
/// left in the world, and position), Cauchy-weighted so that the points of another body that a
/// cluster took in do not pull it. Started from each of `rotations` (the windows' idea of the
/// body's axes, the previous frame's) with the position at the median of those each
/// triangulated keypoint gives; the start that explains the keypoints best wins. nullopt when
/// fewer than `min_inliers` keypoints agree with the result.
std::optional<ObservedPose> ObserveBodyPose(const std::vector<BodyKeypoint>& keypoints,
                                            const std::vector<Eigen::Matrix3d>& rotations,
                                            const Pose& world_from_cam, const StereoCamera& camera,
                                            int min_inliers = 6);

}  // namespace cslam
