#include "backend/reprojection_error.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

namespace cslam {
namespace {

StereoCamera OutdoorCamera() {
  StereoCamera c;
  c.fx = 718.9;
  c.fy = 716.3;
  c.cx = 607.2;
  c.cy = 185.2;
  c.baseline = 0.54;
  c.width = 1242;
  c.height = 375;
  return c;
}

// The residual as Ceres differentiates it automatically (the reference).
struct AutoDiffResidual {
  StereoCamera camera;
  Eigen::Vector3d x;
  Eigen::Matrix3d sqrt_info;
  template <typename T>
  bool operator()(const T* q, const T* t, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t), p(point);
    return WhitenedStereoResidual<T>(camera, x, sqrt_info, rotation * p + translation, residual);
  }
};

TEST(ReprojectionError, ClosedFormJacobiansEqualAutomaticDifferentiation) {
  const StereoCamera camera = OutdoorCamera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    // A random pose — half of the quaternions deliberately not normalised, as during an LM
    // step before the manifold's Plus — and a point 2–60 m in front of the camera.
    Eigen::Quaterniond q(unit(rng), unit(rng), unit(rng), unit(rng));
    q.normalize();
    if (trial % 2) q.coeffs() *= 1.0 + 0.1 * unit(rng);
    const Eigen::Vector3d t(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d p_cam(20 * unit(rng), 5 * unit(rng), 31 + 29 * unit(rng));
    const Eigen::Vector3d point = q.normalized().inverse() * (p_cam - t);
    Eigen::Matrix3d a = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d sqrt_info = a * a.transpose() + Eigen::Matrix3d::Identity();
    const Eigen::Vector3d x(600 + 100 * unit(rng), 180 + 50 * unit(rng), 590 + 100 * unit(rng));

    AutoDiffResidual functor{camera, x, sqrt_info};
    ceres::AutoDiffCostFunction<AutoDiffResidual, 3, 4, 3, 3> reference(
        new AutoDiffResidual(functor));
    const double* parameters[] = {q.coeffs().data(), t.data(), point.data()};
    double r_ref[3], jq_ref[12], jt_ref[9], jp_ref[9];
    double* j_ref[] = {jq_ref, jt_ref, jp_ref};
    const bool ok_ref = reference.Evaluate(parameters, r_ref, j_ref);

    double r[3], jq[12], jt[9], jp[9];
    const bool ok = StereoReprojectionWithJacobians(camera, x, sqrt_info, parameters[0],
                                                    parameters[1], parameters[2], r, jq, jt, jp);
    ASSERT_EQ(ok, ok_ref) << "trial " << trial;
    if (!ok) continue;
    // Rounding only: the dual-number evaluation may order the floating-point operations
    // differently.
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(r[i], r_ref[i], 1e-13 * std::max(1.0, std::abs(r_ref[i]))) << "residual " << i;
    auto near = [](const double* got, const double* want, int n, const char* what, int trial) {
      double scale = 0;
      for (int i = 0; i < n; ++i) scale = std::max(scale, std::abs(want[i]));
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(got[i], want[i], 1e-12 * scale) << what << "[" << i << "], trial " << trial;
    };
    near(jq, jq_ref, 12, "d/dq", trial);
    near(jt, jt_ref, 9, "d/dt", trial);
    near(jp, jp_ref, 9, "d/dpoint", trial);
  }
}

TEST(ReprojectionError, PointBehindTheCameraIsRejectedLikeTheTemplate) {
  const StereoCamera camera = OutdoorCamera();
  const double q[] = {0, 0, 0, 1}, t[] = {0, 0, 0}, point[] = {1, 1, -5};
  double r[3], jq[12];
  EXPECT_FALSE(StereoReprojectionWithJacobians(camera, Eigen::Vector3d(600, 180, 590),
                                               Eigen::Matrix3d::Identity(), q, t, point, r, jq,
                                               nullptr, nullptr));
}

}  // namespace
}  // namespace cslam
