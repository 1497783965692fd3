#include "core/spd3.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

namespace cslam {
namespace {

// A depth-elongated stereo covariance: σ 1 cm across, 5 m along a tilted viewing ray.
Eigen::Matrix3d ElongatedCovariance(double tilt) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  return r * Eigen::Vector3d(1e-4, 1e-4, 25.0).asDiagonal() * r.transpose();
}

Eigen::Matrix3d ElongatedInverse(double tilt) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  return r * Eigen::Vector3d(1e4, 1e4, 0.04).asDiagonal() * r.transpose();
}

TEST(InvertSpd3, MatchesTheExactInverseOnWellAndIllConditionedMatrices) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < 200; ++i) {
    Eigen::Matrix3d a;
    for (int k = 0; k < 9; ++k) a(k) = n(rng);
    const Eigen::Matrix3d s = i % 2 ? Eigen::Matrix3d(a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity())
                                    : ElongatedCovariance(0.01 * i);
    Eigen::Matrix3d inv;
    double det = 0;
    ASSERT_TRUE(InvertSpd3(s, &inv, &det));
    const Eigen::Matrix3d cholesky = s.llt().solve(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d truth = i % 2 ? cholesky : ElongatedInverse(0.01 * i);
    // Cofactors reach only ~6e-8 on the elongated ones (cancellation); a factorisation 2e-11.
    EXPECT_LT((inv - truth).norm(), 1e-9 * truth.norm()) << s;
    // The elongated ones' determinant is known exactly: the product of the variances.
    const double true_det = i % 2 ? s.determinant() : 1e-4 * 1e-4 * 25.0;
    EXPECT_NEAR(det, true_det, (i % 2 ? 1e-12 : 1e-6) * true_det);
    EXPECT_LT((s * inv - Eigen::Matrix3d::Identity()).norm(), 1e-6);
  }
}

TEST(InvertSpd3, RefusesMatricesThatAreNotPositiveDefinite) {
  Eigen::Matrix3d inv = Eigen::Matrix3d::Constant(7);
  double det = 7;
  const Eigen::Matrix3d indefinite = Eigen::Vector3d(1, -1, 1).asDiagonal();
  const Eigen::Matrix3d singular = Eigen::Vector3d(1, 1, 1) * Eigen::Vector3d(1, 1, 1).transpose();
  Eigen::Matrix3d negative_first = Eigen::Matrix3d::Identity();
  negative_first(0, 0) = -1;
  negative_first(1, 1) = -1;  // det > 0 with two negative eigenvalues
  Eigen::Matrix3d not_finite = Eigen::Matrix3d::Identity();
  not_finite(2, 2) = std::numeric_limits<double>::infinity();
  for (const Eigen::Matrix3d& s : {indefinite, singular, negative_first, not_finite,
                                   Eigen::Matrix3d(Eigen::Matrix3d::Zero())}) {
    EXPECT_FALSE(InvertSpd3(s, &inv, &det)) << s;
    EXPECT_EQ(inv, Eigen::Matrix3d::Constant(7));
    EXPECT_EQ(det, 7);
  }
}

}  // namespace
}  // namespace cslam
