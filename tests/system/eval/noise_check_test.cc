#include "system/eval/noise_check.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/cameras.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

StereoCamera Camera() { return testing::KittiSizedCamera(); }

// 200 static landmarks seen over 20 frames by a camera driving along z, observed with noise
// drawn from `scale` × the stated covariance (anisotropic: 0.8 px across, 0.4 px along v,
// correlated uL/uR), a fraction `outliers` of the observations displaced by 15 px; the map
// holds the true poses and positions.
struct Scene {
  MapState map;
  TrackletTable table;
};

Scene MakeScene(double scale, double outliers, unsigned seed) {
  const StereoCamera camera = Camera();
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Matrix3d cov;
  cov << 0.64, 0.0, 0.3, 0.0, 0.16, 0.0, 0.3, 0.0, 0.64;
  const Eigen::Matrix3d l = cov.llt().matrixL();
  MotionEstimate e;
  e.range = {0, 20};
  for (int f = 0; f < 20; ++f) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(0, 0, 0.8 * f);
    e.world_from_cam.push_back(p);
  }
  Scene s;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(-10 + 20 * u(rng), -2 + 3 * u(rng), 25 + 30 * u(rng));
    e.landmark_cluster.push_back(0);
    e.landmark_in_cluster.push_back(p);
    for (int f = 0; f < 20; ++f) {
      Eigen::Vector3d x;
      camera.Project(Eigen::Vector3d(e.world_from_cam[f].inverse() * p), &x);
      x += scale * l * testing::Draw3([&] { return normal(rng); });
      if (u(rng) < outliers) x(0) += 15.0, x(2) += 15.0;
      s.table.Add(i, f, x, cov);
    }
  }
  s.map.Integrate(e);
  return s;
}

TEST(NoiseCheck, HonestCovariancesGiveOnePerDegreeOfFreedom) {
  const Scene s = MakeScene(1.0, 0.0, 1);
  const NoiseCheck n = CheckStaticNoise(s.map, s.table, Camera());
  EXPECT_EQ(n.landmarks, 200);
  EXPECT_EQ(n.observations, 200 * 20);
  EXPECT_NEAR(n.chi2_per_dof, 1.0, 0.05);
  EXPECT_LT(n.cut_fraction, 0.005);  // the gate is the 0.999 quantile
}

TEST(NoiseCheck, NoiseTwiceTheStatedIsFlaggedAndOutliersAreCut) {
  const Scene wide = MakeScene(2.0, 0.0, 2);
  const NoiseCheck twice = CheckStaticNoise(wide.map, wide.table, Camera());
  // The gate (χ²(3) 0.999 of the stated noise) cuts a quarter of the wider noise's
  // observations and the mean of the rest is well above 1: both say "optimistic".
  EXPECT_GT(twice.chi2_per_dof, 2.0);
  EXPECT_GT(twice.cut_fraction, 0.1);
  const Scene s = MakeScene(1.0, 0.05, 3);
  const NoiseCheck n = CheckStaticNoise(s.map, s.table, Camera());
  EXPECT_NEAR(n.cut_fraction, 0.05, 0.01);
  EXPECT_NEAR(n.chi2_per_dof, 1.0, 0.06);
}

}  // namespace
}  // namespace cslam
