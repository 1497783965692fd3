// ClusterSLAM on the synthetic generator's sequences at 0 px keypoint noise: the generator
// then writes 1e-12 px² covariances, and without the backend's covariance floor
// (ClusterSlamOptions::min_pixel_sigma) every χ² test fails — no cluster at all, accuracy 0
// (docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md). Exact measurements
// must give at least the noisy result.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "backend/clusterslam.h"
#include "backend/covariance_floor.h"
#include "system/eval/clustering_metrics.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {
namespace {

struct Outcome {
  double accuracy = 0;
  double camera_rms = 0;  // m, no alignment needed: both worlds are the first camera
};

Outcome RunZeroNoise(const std::string& preset, const ClusterSlamOptions& options) {
  SyntheticOptions o;
  o.preset = preset;
  o.seed = 1;
  o.frames = 100;
  o.noise_px = 0;
  const SyntheticSequence seq = GenerateSynthetic(o);
  const FrameRange range{0, seq.num_frames()};
  const BackendResult r = RunClusterSlam(seq.observations, seq.camera, range, options);
  std::vector<int> truth, predicted;
  for (int l : seq.observations.LandmarksIn(range, 4)) {
    truth.push_back(seq.landmark_object[l]);
    const auto& labels = r.estimate.landmark_cluster;
    predicted.push_back(l < static_cast<int>(labels.size()) ? labels[l] : -1);
  }
  Outcome out;
  out.accuracy = ClusteringAccuracy(truth, predicted);
  double sum = 0;
  for (int f = 0; f < range.size(); ++f)
    sum += (r.estimate.world_from_cam[f].translation() - seq.world_from_cam[f].translation()).squaredNorm();
  out.camera_rms = std::sqrt(sum / range.size());
  std::printf("%s, 0 px, min_pixel_sigma %.2f: accuracy %.3f, camera RMS %.4f m\n", preset.c_str(),
              options.min_pixel_sigma, out.accuracy, out.camera_rms);
  return out;
}

TEST(ZeroNoiseSynthetic, IndoorIsClusteredAndTheCameraExact) {
  const Outcome o = RunZeroNoise("indoor", ClusterSlamOptions::Indoor());
  EXPECT_GE(o.accuracy, 0.9);
  EXPECT_LT(o.camera_rms, 0.01);
}

TEST(ZeroNoiseSynthetic, OutdoorIsClusteredAndTheCameraExact) {
  const Outcome o = RunZeroNoise("outdoor", ClusterSlamOptions::Outdoor());
  EXPECT_GE(o.accuracy, 0.9);
  EXPECT_LT(o.camera_rms, 0.01);
}

TEST(ZeroNoiseSynthetic, WithoutTheFloorNothingIsClustered) {
  // Pins why the floor exists (the 0-px point of the noise sweep).
  ClusterSlamOptions off = ClusterSlamOptions::Indoor();
  off.min_pixel_sigma = 0;
  EXPECT_LT(RunZeroNoise("indoor", off).accuracy, 0.5);
}

TEST(CovarianceFloor, ScalesUpOnlyACovarianceWhoseLargestAxisIsBelowIt) {
  const Eigen::Matrix3d tiny = 1e-12 * Eigen::Matrix3d::Identity();
  EXPECT_TRUE(FloorPixelCovariance(tiny, 0.5).isApprox(0.25 * Eigen::Matrix3d::Identity()));
  // The frontend's shape: uR = uL − d, so Σ = A diag(σL², σL², σd²) Aᵀ. At its smallest
  // (σL = 0.5, σd = 0.3 px) the disparity direction is thin, and it must stay so.
  Eigen::Matrix3d a;
  a << 1, 0, 0, 0, 1, 0, 1, 0, -1;
  const Eigen::Matrix3d frontend_min = a * Eigen::Vector3d(0.25, 0.25, 0.09).asDiagonal() * a.transpose();
  EXPECT_TRUE(FloorPixelCovariance(frontend_min, 0.5).isApprox(frontend_min));
  // A small anisotropic one is scaled as a whole: largest axis to the floor, shape kept.
  const Eigen::Matrix3d small = 1e-4 * frontend_min;
  const Eigen::Matrix3d floored = FloorPixelCovariance(small, 0.5);
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(floored).eigenvalues();
  EXPECT_NEAR(ev.maxCoeff(), 0.25, 1e-9);
  const Eigen::Vector3d ev0 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(small).eigenvalues();
  EXPECT_NEAR(ev.minCoeff() / ev.maxCoeff(), ev0.minCoeff() / ev0.maxCoeff(), 1e-9);
}

TEST(CovarianceFloor, ATableAboveTheFloorIsNotCopied) {
  TrackletTable t;
  t.Add(0, 0, Eigen::Vector3d(10, 10, 5), Eigen::Matrix3d::Identity());
  t.Add(1, 1, Eigen::Vector3d(10, 10, 5), Eigen::Matrix3d::Identity());
  EXPECT_FALSE(FloorPixelCovariances(t, {0, 2}, 0.5).has_value());
  t.Add(2, 1, Eigen::Vector3d(20, 10, 5), 1e-12 * Eigen::Matrix3d::Identity());
  const auto floored = FloorPixelCovariances(t, {0, 2}, 0.5);
  ASSERT_TRUE(floored.has_value());
  EXPECT_EQ(floored->num_landmarks(), t.num_landmarks());
  EXPECT_EQ(floored->num_observations(), t.num_observations());
  EXPECT_NEAR(floored->ObservationsOf(2)[0].cov(0, 0), 0.25, 1e-12);
  EXPECT_NEAR(floored->ObservationsOf(0)[0].cov(0, 0), 1.0, 1e-12);
}

}  // namespace
}  // namespace cslam
