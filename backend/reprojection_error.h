#pragma once
// The bundle adjustment's residual (clusterslam_spec.md §6): the stereo reprojection error of
// a point X in a body frame seen through one pose cam_from_body = (q, t), whitened by the
// square root of the keypoint's information, r = S (x − π(R(q) X + t)).
//
// Two evaluations of the same expression: a template for Ceres' automatic differentiation (the
// coupled solves compose two poses), and closed-form Jacobians [ours, measured]: the decoupled
// solves evaluate this residual tens of thousands of times per LM iteration, and the dual-number
// evaluation cost more than the rest of the Jacobian assembly
// (docs/experiments/2026-11-23-backend-speed.md). Both differentiate the literal expression Ceres
// sees — Eigen's quaternion-times-vector, which does not normalise q — so they agree to rounding.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/stereo_camera.h"

namespace cslam {

/// r = S (x − π(p_in_cam)); false when the point is not in front of the camera (r unset).
template <typename T>
bool WhitenedStereoResidual(const StereoCamera& camera, const Eigen::Vector3d& x,
                            const Eigen::Matrix3d& sqrt_info,
                            const Eigen::Matrix<T, 3, 1>& p_in_cam, T* residual) {
  Eigen::Matrix<T, 3, 1> predicted;
  if (!camera.Project(p_in_cam, &predicted)) return false;
  const Eigen::Matrix<T, 3, 1> e = x.cast<T>() - predicted;
  Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
  r = sqrt_info.cast<T>() * e;
  return true;
}

/// The residual and, for each non-null pointer, its Jacobian (row-major 3×4 w.r.t. the
/// quaternion q = (x, y, z, w) in Eigen's storage order, 3×3 w.r.t. t and w.r.t. the point),
/// the layout Ceres' CostFunction::Evaluate expects. Returns false as the template does.
bool StereoReprojectionWithJacobians(const StereoCamera& camera, const Eigen::Vector3d& x,
                                     const Eigen::Matrix3d& sqrt_info, const double* q,
                                     const double* t, const double* point, double* residual,
                                     double* d_q, double* d_t, double* d_point);

}  // namespace cslam
