#pragma once
// Shared assertions for geometry tests.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

namespace cslam::testing {

/// Element-wise |a - b| <= tol.
template <typename A, typename B>
::testing::AssertionResult MatrixNear(const A& a, const B& b, double tol) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    return ::testing::AssertionFailure() << "size mismatch";
  const double err = (a - b).cwiseAbs().maxCoeff();
  if (err <= tol) return ::testing::AssertionSuccess();
  std::ostringstream s;
  s << "max |a-b| = " << err << " > " << tol << "\na =\n" << a << "\nb =\n" << b;
  return ::testing::AssertionFailure() << s.str();
}

/// Rotation angle and translation distance between two poses within tolerances.
inline ::testing::AssertionResult PoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                           double rot_tol_rad, double trans_tol_m) {
  const Eigen::AngleAxisd aa(a.linear().transpose() * b.linear());
  const double dt = (a.translation() - b.translation()).norm();
  if (std::abs(aa.angle()) <= rot_tol_rad && dt <= trans_tol_m)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "rotation differs by " << aa.angle()
                                       << " rad, translation by " << dt << " m";
}

}  // namespace cslam::testing
