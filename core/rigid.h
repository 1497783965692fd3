#pragma once
// Rigid and similarity transforms. Poses are Eigen::Isometry3d named `b_from_a`: it maps
// points expressed in frame a into frame b, and composes as c_from_a = c_from_b * b_from_a.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace cslam {

using Pose = Eigen::Isometry3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Rotation matrix of the rotation vector `w` (axis * angle, radians).
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w);
/// Rotation vector of R, angle in [0, pi].
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);
/// Angle of R in radians, in [0, pi], robust near 0 and pi.
double RotationAngle(const Eigen::Matrix3d& R);
/// Pose from (rotation vector, translation) = xi(0..2), xi(3..5).
Pose PoseFromVector(const Vector6d& xi);
/// Inverse of PoseFromVector.
Vector6d PoseToVector(const Pose& pose);

/// A similarity transform: dst = scale * R * src + t.
struct Sim3 {
  double scale = 1.0;
  Pose rigid = Pose::Identity();
  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const {
    return scale * (rigid.linear() * p) + rigid.translation();
  }
};

/// Least-squares alignment (Umeyama 1991) of corresponding points: returns the transform
/// mapping `src` onto `dst`. `with_scale` = false gives SE(3). Needs >= 3 points that are not
/// all collinear for a unique answer (fewer: the translation-only or identity fallback).
Sim3 AlignUmeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                  bool with_scale);

/// Mean of two poses weighted by `t` in [0,1] (slerp on rotation, lerp on translation).
Pose Interpolate(const Pose& a, const Pose& b, double t);

}  // namespace cslam
