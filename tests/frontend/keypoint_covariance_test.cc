#include "frontend/keypoint_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "tests/frontend/synthetic_images.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

const cv::Size kSize(320, 160);

void ExpectSymmetricPositiveDefinite(const Eigen::Matrix3d& cov) {
  EXPECT_TRUE(testing::MatrixNear(cov, cov.transpose(), 1e-12));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << cov;
  EXPECT_TRUE(cov.allFinite());
}

TEST(KeypointCovariance, IsSymmetricPositiveDefiniteOnTextureFlatAndEdgeAndBorder) {
  cv::Mat image = testing::RandomTexture(kSize, 21);
  image(cv::Rect(0, 0, 80, 80)).setTo(128);   // flat
  image(cv::Rect(100, 0, 40, 80)).setTo(30);  // vertical edge at x = 140
  image(cv::Rect(140, 0, 40, 80)).setTo(220);
  const KeypointCovarianceOptions o;
  for (const cv::Point2f p : {cv::Point2f(200, 120), cv::Point2f(40, 40), cv::Point2f(140, 40),
                              cv::Point2f(0, 0), cv::Point2f(319, 159)})
    for (int level : {0, 2})
      for (double fb : {0.0, 0.4})
        for (double ncc : {1.0, 0.8, -0.5})
          ExpectSymmetricPositiveDefinite(KeypointCovariance(image, {p, level, fb, ncc, 0.2}, o));
}

TEST(KeypointCovariance, RightColumnInheritsTheLeftErrorAndDisparityHasItsOwn) {
  // Σ = A diag(Σ_left, σ²_d) Aᵀ with uR = uL − d: cov(uL, uR) = var(uL) and
  // var(uL − uR) = σ²_d = (σ_stereo s^ℓ)² + 2σ_n²/G_xx.
  const cv::Mat image = testing::RandomTexture(kSize, 22);
  KeypointCovarianceOptions o;
  o.image_noise_grey = 0;  // floors only: every term known in closed form
  const Eigen::Matrix3d cov = KeypointCovariance(image, {{150, 80}, 1, 0.6}, o);
  const double left_var = std::pow(o.detection_sigma_px * o.level_scale, 2) + 0.3 * 0.3;
  const double disp_var = std::pow(o.stereo_sigma_px * o.level_scale, 2);
  Eigen::Matrix3d expected;
  expected << left_var, 0, left_var, 0, left_var, 0, left_var, 0, left_var + disp_var;
  EXPECT_TRUE(testing::MatrixNear(cov, expected, 1e-12));
}

TEST(KeypointCovariance, IsLargerAlongAnEdgeThanAcrossIt) {
  // A vertical step: x is well localised (strong ∂I/∂x), y is not (aperture problem).
  cv::Mat image(kSize, CV_8U, cv::Scalar(40));
  image(cv::Rect(160, 0, 160, 160)).setTo(200);
  const KeypointCovarianceOptions o;
  const Eigen::Matrix3d cov = KeypointCovariance(image, {{160, 80}, 0, 0}, o);
  EXPECT_GT(cov(1, 1), 10 * cov(0, 0));
  EXPECT_LE(cov(1, 1), std::pow(o.detection_sigma_px, 2) + std::pow(o.max_sigma_px, 2) + 1e-9);
}

TEST(KeypointCovariance, GrowsWithPyramidLevelTrackingResidualAndWeakStereoPeak) {
  const cv::Mat image = testing::RandomTexture(kSize, 23);
  const KeypointCovarianceOptions o;
  const cv::Point2f p(150, 80);
  const Eigen::Matrix3d base = KeypointCovariance(image, {p, 0, 0}, o);
  const Eigen::Matrix3d coarse = KeypointCovariance(image, {p, 1, 0}, o);
  const Eigen::Matrix3d shaky = KeypointCovariance(image, {p, 0, 1.0}, o);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(coarse(k, k), base(k, k));
    EXPECT_GT(shaky(k, k), base(k, k));
  }
  // A weaker, blunter stereo peak only widens the disparity: uL and vL stay as they are.
  const Eigen::Matrix3d sharp = KeypointCovariance(image, {p, 0, 0, 0.95, 0.4}, o);
  const Eigen::Matrix3d blunt = KeypointCovariance(image, {p, 0, 0, 0.80, 0.1}, o);
  EXPECT_TRUE(testing::MatrixNear(sharp.topLeftCorner<2, 2>(), blunt.topLeftCorner<2, 2>(), 1e-12));
  const auto disparity_var = [](const Eigen::Matrix3d& c) {
    return c(0, 0) + c(2, 2) - 2 * c(0, 2);
  };
  EXPECT_NEAR(disparity_var(blunt) - disparity_var(sharp),
              o.match_weight * (0.2 / 0.1 - 0.05 / 0.4), 1e-9);
}

}  // namespace
}  // namespace cslam
