#include "backend/bundle_adjustment.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/backend/synthetic_bodies.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

using testing::Ate;
using testing::BodyScene;
using testing::BodySceneSpec;
using testing::MakeBodyScene;

MotionEstimate Initialise(const BodyScene& scene, const MotionEstimationOptions& base = {}) {
  MotionEstimationOptions o = base;
  o.run_bundle_adjustment = false;
  return EstimateMotions(scene.table, scene.camera, {0, scene.table.num_frames()}, scene.labels, o);
}

/// Mean centroid-track RMSE of the moving clusters (see CentroidTrackRmse).
double ObjectError(const BodyScene& scene, const MotionEstimate& est) {
  double sum = 0.0;
  for (const ClusterMotion& m : est.clusters)
    sum += testing::CentroidTrackRmse(scene, est, m.cluster);
  return est.clusters.empty() ? 0.0 : sum / est.clusters.size();
}

TEST(BundleAdjustment, LowersChi2AndMovesPosesTowardsTheTruth) {
  BodySceneSpec spec;
  spec.pixel_sigma = 1.5;
  const BodyScene scene = MakeBodyScene(spec);
  MotionEstimate est = Initialise(scene);
  const double ate_before = Ate(est.world_from_cam, scene.world_from_cam);
  const double obj_before = ObjectError(scene, est);
  BundleAdjustmentOptions o;
  const BundleAdjustmentSummary s = AdjustBundle(scene.table, scene.camera, o, &est);
  const double ate_after = Ate(est.world_from_cam, scene.world_from_cam);
  const double obj_after = ObjectError(scene, est);
  std::printf(
      "BA: chi2 %.1f -> %.1f (%d residuals), camera ATE %.4f -> %.4f, objects %.4f -> %.4f\n",
      s.initial_chi2, s.final_chi2, s.num_residuals, ate_before, ate_after, obj_before, obj_after);
  EXPECT_TRUE(s.usable);
  EXPECT_LT(s.final_chi2, 0.9 * s.initial_chi2);
  // At convergence the χ² per residual is close to its expectation, 3 − (unknowns / residuals).
  EXPECT_LT(s.final_chi2 / s.num_residuals, 3.0);
  EXPECT_LT(ate_after, ate_before);
  EXPECT_LT(obj_after, obj_before);
  EXPECT_DOUBLE_EQ(est.chi2, s.final_chi2);
}

TEST(BundleAdjustment, RobustKernelsResistGrossOutliers) {
  BodySceneSpec spec;
  spec.num_moving = 0;
  spec.num_static = 250;
  spec.gross_outlier_fraction = 0.05;
  spec.gross_outlier_px = 25.0;
  const BodyScene scene = MakeBodyScene(spec);
  double ate[3];
  for (RobustKernel kernel : {RobustKernel::kNone, RobustKernel::kHuber, RobustKernel::kDcs}) {
    MotionEstimationOptions o;
    o.bundle_adjustment.robust_kernel = kernel;
    o.bundle_adjustment.max_iterations = 50;
    const MotionEstimate est =
        EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, o);
    ate[static_cast<int>(kernel)] = Ate(est.world_from_cam, scene.world_from_cam);
  }
  std::printf("outliers: camera ATE none %.4f, huber %.4f, dcs %.4f\n", ate[0], ate[1], ate[2]);
  EXPECT_LT(ate[1], 0.7 * ate[0]);
  EXPECT_LT(ate[2], 0.7 * ate[0]);
}

TEST(BundleAdjustment, CouplingModesAgreeOnACleanScene) {
  BodySceneSpec spec;
  spec.pixel_sigma = 0.3;
  const BodyScene scene = MakeBodyScene(spec);
  std::vector<MotionEstimate> results;
  for (BaCoupling c :
       {BaCoupling::kDecoupled, BaCoupling::kSemiCoupled, BaCoupling::kFullyCoupled}) {
    MotionEstimationOptions o;
    o.bundle_adjustment.coupling = c;
    o.bundle_adjustment.max_iterations = 50;
    results.push_back(
        EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, o));
  }
  for (size_t m = 1; m < results.size(); ++m) {
    for (int f = 0; f < spec.num_frames; ++f)
      EXPECT_TRUE(cslam::testing::PoseNear(results[m].world_from_cam[f],
                                           results[0].world_from_cam[f], 1e-3, 3e-3))
          << "mode " << m << " frame " << f;
    // A moving cluster's frame is a gauge: compare where its landmarks are in the world.
    ASSERT_EQ(results[m].clusters.size(), results[0].clusters.size());
    for (const ClusterMotion& ref : results[0].clusters) {
      const ClusterMotion* other = results[m].FindCluster(ref.cluster);
      ASSERT_NE(other, nullptr);
      ASSERT_EQ(other->frames, ref.frames);
      double max_err = 0.0;
      for (size_t i = 0; i < scene.labels.size(); ++i) {
        if (results[0].landmark_cluster[i] != ref.cluster) continue;
        for (size_t k = 0; k < ref.frames.size(); ++k)
          max_err =
              std::max(max_err, (ref.world_from_cluster[k] * results[0].landmark_in_cluster[i] -
                                 other->world_from_cluster[k] * results[m].landmark_in_cluster[i])
                                    .norm());
      }
      EXPECT_LT(max_err, 0.01) << "mode " << m << " cluster " << ref.cluster;
    }
    EXPECT_NEAR(results[m].chi2, results[0].chi2, 0.02 * results[0].chi2);
  }
}

TEST(BundleAdjustment, EnumsParseAndOptionsLoad) {
  EXPECT_EQ(ParseRobustKernel("dcs", "k"), RobustKernel::kDcs);
  EXPECT_EQ(ParseBaCoupling(ToString(BaCoupling::kSemiCoupled), "k"), BaCoupling::kSemiCoupled);
  EXPECT_THROW(ParseRobustKernel("cauchy", "k"), ConfigError);
  auto reader = OptionsReader::FromString(
      "coupling: fully_coupled\nrobust_kernel: none\nmax_iterations: 7\n", "t");
  BundleAdjustmentOptions o;
  o.Load(reader);
  reader.Finish();
  EXPECT_EQ(o.coupling, BaCoupling::kFullyCoupled);
  EXPECT_EQ(o.robust_kernel, RobustKernel::kNone);
  EXPECT_EQ(o.max_iterations, 7);
  o.num_threads = 0;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
