#pragma once
// [ours, beyond the paper] A constant-velocity prior on a moving cluster's poses in three
// consecutive frames. Why: a cluster's pose in one frame rests only on that frame's
// observations of its points, and a far car holds a few points whose stereo depth is metres
// uncertain each; its trajectory then jumps from frame to frame although no car moves like
// that (docs/experiments/2026-12-03-object-pose-noise-and-motion-prior.md).
//
// The residual is taken at the body's centre in the world, so it does not depend on where the
// cluster's (arbitrary) frame has its origin:
//   r = [ (p_a − 2 p_b + p_c) / σ_m ;  (Log(Q_aᵀ Q_b) − Log(Q_bᵀ Q_c)) / σ_rad ]
// with Q_i the body's rotation in the world and p_i its centre's world position at frame i.
// Its cost is robust (Huber on ‖r‖², kMotionPriorHuberChi2): a car entering a junction's arc
// changes its yaw rate by far more than σ in one frame, and such a real manoeuvre should cost
// linearly, not be smoothed away.
#include <ceres/rotation.h>

#include <Eigen/Geometry>

#include "core/rigid.h"

namespace cslam {

/// Where the prior's cost turns from quadratic to linear: χ²(6 dof) at 95 %.
inline constexpr double kMotionPriorHuberChi2 = 12.59;

/// One prior term: three consecutive frames of one body. The camera poses are held (the
/// moving-cluster solve does not estimate them); the unknowns are the body's three
/// cam_from_body poses.
struct MotionPriorTerm {
  Pose world_from_cam[3] = {Pose::Identity(), Pose::Identity(), Pose::Identity()};
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< in the body's frame
  double sigma_m = 0.05;    ///< of the centre's second difference, metres per frame²
  double sigma_rad = 0.01;  ///< of the change of the per-frame rotation, radians
};

/// The 6 residuals of `term` for the cam_from_body pose blocks (Eigen quaternion x, y, z, w,
/// then translation) of its three frames.
template <typename T>
void MotionPriorResidual(const MotionPriorTerm& term, const T* a, const T* b, const T* c, T* r) {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  const T* blocks[3] = {a, b, c};
  Eigen::Quaternion<T> q[3];
  Vec3 p[3];
  const Vec3 centre = term.centre.cast<T>();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Map<const Eigen::Quaternion<T>> cam_q(blocks[i]);
    const Eigen::Map<const Vec3> cam_t(blocks[i] + 4);
    const Eigen::Quaterniond world_q(term.world_from_cam[i].linear());
    q[i] = world_q.cast<T>() * cam_q;
    p[i] = term.world_from_cam[i].linear().cast<T>() * (cam_q * centre + cam_t) +
           term.world_from_cam[i].translation().cast<T>();
  }
  const Vec3 second = (p[0] - T(2) * p[1] + p[2]) / T(term.sigma_m);
  T steps[2][3];
  for (int i = 0; i < 2; ++i) {
    const Eigen::Quaternion<T> d = q[i].conjugate() * q[i + 1];
    const T wxyz[4] = {d.w(), d.x(), d.y(), d.z()};
    ceres::QuaternionToAngleAxis(wxyz, steps[i]);
  }
  for (int k = 0; k < 3; ++k) {
    r[k] = second(k);
    r[3 + k] = (steps[1][k] - steps[0][k]) / T(term.sigma_rad);
  }
}

}  // namespace cslam
