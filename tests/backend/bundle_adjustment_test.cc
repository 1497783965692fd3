#include "backend/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "backend/disparity_offset.h"
#include "backend/motion_estimation.h"
#include "core/errors.h"
#include "tests/backend/synthetic_bodies.h"
#include "tests/backend/test_scene.h"
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

// A solve that cannot be used (here: one observation's covariance is NaN, as a broken
// covariance model would give) leaves the estimate as it was given, marked, on either solver;
// the same scene without it adjusts normally.
TEST(BundleAdjustment, AnUnusableSolveGivesBackTheEstimateItWasGivenMarked) {
  BodySceneSpec spec;
  spec.pixel_sigma = 1.5;
  const BodyScene scene = MakeBodyScene(spec);
  int bad_landmark = 0;  // a static landmark seen at frame 3
  while (scene.labels[bad_landmark] != 0 ||
         scene.table.ObservationsOf(bad_landmark, {3, 4}).empty())
    ++bad_landmark;
  TrackletTable broken;
  for (int l = 0; l < scene.table.num_landmarks(); ++l)
    for (const StereoObservation& o : scene.table.ObservationsOf(l))
      broken.Add(l, o.frame, o.x,
                 l == bad_landmark && o.frame == 3 ? Eigen::Matrix3d::Constant(NAN) : o.cov);
  for (const bool native : {true, false}) {
    SCOPED_TRACE(native ? "native solver" : "Ceres");
    BundleAdjustmentOptions o;
    o.native_dense_solver = native;
    MotionEstimate good = Initialise(scene);
    EXPECT_TRUE(AdjustBundle(scene.table, scene.camera, o, &good).usable);
    EXPECT_FALSE(good.adjustment_failed);

    MotionEstimate bad = Initialise(scene);
    const MotionEstimate given = bad;
    const BundleAdjustmentSummary s = AdjustBundle(broken, scene.camera, o, &bad);
    EXPECT_FALSE(s.usable);
    EXPECT_FALSE(s.why.empty());
    EXPECT_TRUE(bad.adjustment_failed);
    ASSERT_EQ(bad.world_from_cam.size(), given.world_from_cam.size());
    for (size_t k = 0; k < bad.world_from_cam.size(); ++k)
      EXPECT_TRUE(bad.world_from_cam[k].isApprox(given.world_from_cam[k], 0.0)) << k;
    for (size_t i = 0; i < bad.landmark_in_cluster.size(); ++i)
      if (bad.landmark_in_cluster[i].allFinite())
        EXPECT_EQ(bad.landmark_in_cluster[i], given.landmark_in_cluster[i]) << i;
  }
}

// An online window's frames the map already has (backend/clusterslam.h, fix_known_poses):
// those poses come out bit for bit as they went in, the rest are still estimated — on a scene
// whose held poses are the truth, the free frames end as close to it as a free adjustment
// gets them, and the static points follow the held poses.
TEST(BundleAdjustment, FixedCamerasStayPutAndTheFreeOnesReachTheTruth) {
  BodySceneSpec spec;
  spec.pixel_sigma = 1.0;
  const BodyScene scene = MakeBodyScene(spec);
  const int n = scene.table.num_frames();
  const int known = n - 5;  // as in a warm window: all but the newest 5 frames from the map
  MotionEstimate start = Initialise(scene);
  std::vector<bool> fixed(n, false);
  for (int k = 0; k < known; ++k) {
    fixed[k] = true;
    start.world_from_cam[k] = scene.world_from_cam[k];
  }
  MotionEstimate held = start, free = start;
  BundleAdjustmentOptions o;
  const BundleAdjustmentSummary s = AdjustBundle(scene.table, scene.camera, o, &held, nullptr, &fixed);
  AdjustBundle(scene.table, scene.camera, o, &free);
  EXPECT_TRUE(s.usable);
  EXPECT_LT(s.final_chi2, 0.9 * s.initial_chi2);
  for (int k = 0; k < known; ++k)
    EXPECT_TRUE(held.world_from_cam[k].matrix() == start.world_from_cam[k].matrix()) << k;
  // Static landmarks only held cameras see are decoupled from the rest and stay where they were.
  int untouched = 0;
  for (int i = 0; i < scene.table.num_landmarks(); ++i) {
    if (start.landmark_cluster[i] != 0) continue;
    bool only_held = true;
    for (const StereoObservation& obs : scene.table.ObservationsOf(i, {0, n})) only_held &= obs.frame < known;
    if (!only_held) continue;
    EXPECT_TRUE(held.landmark_in_cluster[i] == start.landmark_in_cluster[i]) << i;
    ++untouched;
  }
  EXPECT_GT(untouched, 0);
  auto new_frame_error = [&](const MotionEstimate& e) {
    double sum = 0;
    for (int k = known; k < n; ++k)
      sum += (e.world_from_cam[k].translation() - scene.world_from_cam[k].translation()).squaredNorm();
    return std::sqrt(sum / (n - known));
  };
  auto start_error = new_frame_error(start);
  std::printf("fixed cameras: new frames %.4f -> %.4f m (free adjustment %.4f m)\n", start_error,
              new_frame_error(held), new_frame_error(free));
  EXPECT_LT(new_frame_error(held), 0.5 * start_error);
  EXPECT_LT(new_frame_error(held), new_frame_error(free) + 0.002);
  EXPECT_LT(ObjectError(scene, held), ObjectError(scene, start));
  // A free adjustment moves the known frames (the test would pin nothing otherwise).
  bool moved = false;
  for (int k = 1; k < known; ++k) moved |= !(free.world_from_cam[k].matrix() == start.world_from_cam[k].matrix());
  EXPECT_TRUE(moved);
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

/// Largest distance between the two estimates' world positions of the same landmark at any
/// frame of its cluster (a moving cluster's own frame is a gauge, its world points are not).
double MaxWorldPointDifference(const MotionEstimate& a, const MotionEstimate& b) {
  double max_err = 0.0;
  for (size_t i = 0; i < a.landmark_cluster.size(); ++i) {
    const int label = a.landmark_cluster[i];
    if (label < 0 || !a.landmark_in_cluster[i].allFinite()) continue;
    if (label == 0) {
      max_err = std::max(max_err, (a.landmark_in_cluster[i] - b.landmark_in_cluster[i]).norm());
      continue;
    }
    const ClusterMotion* ma = a.FindCluster(label);
    const ClusterMotion* mb = b.FindCluster(label);
    if (!ma || !mb || ma->frames != mb->frames) return std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < ma->frames.size(); ++k)
      max_err = std::max(max_err, (ma->world_from_cluster[k] * a.landmark_in_cluster[i] -
                                   mb->world_from_cluster[k] * b.landmark_in_cluster[i])
                                      .norm());
  }
  return max_err;
}

// Every linear solver / library / Jacobian choice minimises the same cost: run to
// convergence from the same start they reach the reference's minimum (SuiteSparse normal
// Cholesky, closed-form Jacobians) — to rounding for the direct solvers, to the inexact
// steps' tolerance for conjugate gradients.
TEST(BundleAdjustment, SolverChoicesReachTheReferenceSolution) {
  BodySceneSpec spec;
  spec.num_static = 150;
  spec.points_per_body = 30;
  const BodyScene scene = MakeBodyScene(spec);
  const MotionEstimate initial = Initialise(scene);
  BundleAdjustmentOptions reference;
  reference.max_iterations = 200;
  reference.function_tolerance = 1e-12;
  reference.sparse_schur_min_poses = 0;  // every solve sparse, also the moving clusters'
  reference.native_sparse_solver = false;  // Ceres' sparse solvers are the reference
  MotionEstimate ref = initial;
  const BundleAdjustmentSummary ref_summary =
      AdjustBundle(scene.table, scene.camera, reference, &ref);
  ASSERT_TRUE(ref_summary.usable);
  ASSERT_LT(ref_summary.final_chi2, 0.5 * ref_summary.initial_chi2);

  struct Variant {
    const char* name;
    BundleAdjustmentOptions options;
    double pose_tol_m, rot_tol_rad, point_tol_m, chi2_rel;
  };
  std::vector<Variant> variants;
  auto add = [&](const char* name, auto&& change, double pose_tol_m, double rot_tol_rad,
                 double point_tol_m, double chi2_rel) {
    BundleAdjustmentOptions o = reference;
    change(o);
    variants.push_back({name, o, pose_tol_m, rot_tol_rad, point_tol_m, chi2_rel});
  };
  add("dense_schur",
      [](BundleAdjustmentOptions& o) {
        o.sparse_schur_min_poses = 1000;
        o.native_dense_solver = false;
      },
      1e-6, 1e-7, 1e-5, 1e-8);
  // The moving clusters (30 points in 30 frames) eliminate their poses first by default.
  add("dense_schur_points_first",
      [](BundleAdjustmentOptions& o) {
        o.sparse_schur_min_poses = 1000;
        o.dense_schur_smaller_side = false;
        o.native_dense_solver = false;
      },
      1e-6, 1e-7, 1e-5, 1e-8);
  // backend/stereo_lm.h: its own LM path, the same minimum.
  add("native_dense",
      [](BundleAdjustmentOptions& o) {
        o.sparse_schur_min_poses = 1000;
        o.native_dense_solver = true;
      },
      1e-6, 1e-7, 1e-5, 1e-8);
  // backend/stereo_lm.h on the large solves: the reduced systems factored by their profile.
  add("native_profile", [](BundleAdjustmentOptions& o) { o.native_sparse_solver = true; }, 1e-6,
      1e-7, 1e-5, 1e-8);
  add("sparse_schur", [](BundleAdjustmentOptions& o) { o.sparse_solver = SparseSolver::kSchur; },
      1e-6, 1e-7, 1e-5, 1e-8);
  add("eigen_normal_cholesky",
      [](BundleAdjustmentOptions& o) { o.sparse_library = SparseLibrary::kEigen; }, 1e-6, 1e-7,
      1e-5, 1e-8);
  add("eigen_schur",
      [](BundleAdjustmentOptions& o) {
        o.sparse_library = SparseLibrary::kEigen;
        o.sparse_solver = SparseSolver::kSchur;
      },
      1e-6, 1e-7, 1e-5, 1e-8);
  add("autodiff", [](BundleAdjustmentOptions& o) { o.analytic_jacobians = false; }, 1e-6, 1e-7,
      1e-5, 1e-8);
  // Conjugate gradients stop at a relative residual, so the minimum is reached to ~1e-4.
  add("iterative_schur",
      [](BundleAdjustmentOptions& o) { o.sparse_solver = SparseSolver::kIterativeSchur; }, 2e-4,
      2e-5, 2e-3, 1e-4);
  for (const Variant& v : variants) {
    MotionEstimate est = initial;
    const BundleAdjustmentSummary s = AdjustBundle(scene.table, scene.camera, v.options, &est);
    EXPECT_TRUE(s.usable) << v.name;
    EXPECT_NEAR(s.final_chi2, ref_summary.final_chi2, v.chi2_rel * ref_summary.final_chi2)
        << v.name;
    for (int f = 0; f < spec.num_frames; ++f)
      EXPECT_TRUE(cslam::testing::PoseNear(est.world_from_cam[f], ref.world_from_cam[f],
                                           v.rot_tol_rad, v.pose_tol_m))
          << v.name << " frame " << f;
    const double point_diff = MaxWorldPointDifference(est, ref);
    std::printf("%s: chi2 %.6f (reference %.6f), landmarks within %.2e m\n", v.name,
                s.final_chi2, ref_summary.final_chi2, point_diff);
    EXPECT_LT(point_diff, v.point_tol_m) << v.name;
  }
}

// A street seen by the outdoor camera (fx 640, baseline 0.5 m) driving 1 m a frame: static
// points 4–120 m ahead, disparities from ~3 px to 80 px. `shift_px` is added to every right
// column (the disparity shrinks by it), as an unstated rectification offset would.
testing::TestScene OffsetStreet(double shift_px) {
  const testing::TestBody street{
      testing::RandomPoints(800, {-15, -3, 4}, {15, 3, 120}, 41),
      [](int) { return Pose::Identity(); }};
  testing::TestScene s = testing::MakeScene(
      testing::SyntheticCamera(true), {street}, 25,
      [](int t) { return testing::YawPose(0.01 * t, Eigen::Vector3d(0.1 * t, 0.0, 1.0 * t)); },
      0.3, 0.3, 42);
  s.table = CorrectDisparities(s.table, -shift_px);
  return s;
}

// |estimated / true distance from the first to the last camera − 1|.
double ScaleError(const testing::TestScene& s, double far_depth_baselines) {
  MotionEstimationOptions o;
  o.bundle_adjustment.far_depth_baselines = far_depth_baselines;
  const std::vector<int> labels(s.truth.size(), 0);
  const MotionEstimate est =
      EstimateMotions(s.table, s.camera, {0, s.table.num_frames()}, labels, o);
  const double truth =
      (s.world_from_cam.back().translation() - s.world_from_cam.front().translation()).norm();
  const double estimated =
      (est.world_from_cam.back().translation() - est.world_from_cam.front().translation()).norm();
  return std::abs(estimated / truth - 1.0);
}

TEST(BundleAdjustment, FarPointsWithoutDisparityKeepAnOffsetFromScalingTheCamera) {
  const testing::TestScene shifted = OffsetStreet(0.3);
  const double all = ScaleError(shifted, 0.0);
  const double near_only = ScaleError(shifted, 35.0);
  const double clean = ScaleError(OffsetStreet(0.0), 35.0);
  std::printf("0.3 px offset: scale error %.4f with every disparity, %.4f with far points' "
              "disparities down-weighted; no offset, down-weighted: %.4f\n",
              all, near_only, clean);
  // An offset δ stretches depths by δ / d: the far points pull the scale most.
  EXPECT_GT(all, 0.01);
  EXPECT_LT(near_only, 0.6 * all);
  // Without an offset the near points alone still carry the scale.
  EXPECT_LT(clean, 0.005);
}

TEST(BundleAdjustment, EnumsParseAndOptionsLoad) {
  EXPECT_EQ(ParseEnum(kRobustKernelNames, "dcs", "k"), RobustKernel::kDcs);
  EXPECT_EQ(ParseEnum(kBaCouplingNames, NameOf(kBaCouplingNames, BaCoupling::kSemiCoupled), "k"),
            BaCoupling::kSemiCoupled);
  EXPECT_THROW(ParseEnum(kRobustKernelNames, "cauchy", "k"), ConfigError);
  auto reader = OptionsReader::FromString(
      "coupling: fully_coupled\nrobust_kernel: none\nmax_iterations: 7\n", "t");
  BundleAdjustmentOptions o;
  reader.LoadInto(&o);
  EXPECT_EQ(o.coupling, BaCoupling::kFullyCoupled);
  EXPECT_EQ(o.robust_kernel, RobustKernel::kNone);
  EXPECT_EQ(o.max_iterations, 7);
  EXPECT_EQ(ParseEnum(kSparseSolverNames,
                      NameOf(kSparseSolverNames, SparseSolver::kIterativeSchur), "k"),
            SparseSolver::kIterativeSchur);
  EXPECT_EQ(ParseEnum(kSparseLibraryNames, NameOf(kSparseLibraryNames, SparseLibrary::kEigen), "k"),
            SparseLibrary::kEigen);
  EXPECT_THROW(ParseEnum(kSparseSolverNames, "cgnr", "k"), ConfigError);
  EXPECT_THROW(ParseEnum(kSparseLibraryNames, "cxsparse", "k"), ConfigError);
  // A misspelt word in a file names the key and lists the words.
  try {
    auto bad = OptionsReader::FromString("robust_kernel: cauchy\n", "t.yaml");
    BundleAdjustmentOptions b;
    bad.LoadInto(&b);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("robust_kernel"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("none, huber, dcs"), std::string::npos) << e.what();
  }
  auto reader2 = OptionsReader::FromString(
      "sparse_solver: iterative_schur\nsparse_library: eigen\n", "t");
  BundleAdjustmentOptions o2;
  reader2.LoadInto(&o2);
  EXPECT_EQ(o2.sparse_solver, SparseSolver::kIterativeSchur);
  EXPECT_EQ(o2.sparse_library, SparseLibrary::kEigen);
  o.num_threads = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  auto reader3 = OptionsReader::FromString(
      "far_depth_baselines: 35\nfar_disparity_sigma_px: 5\n", "t");
  BundleAdjustmentOptions o3;
  reader3.LoadInto(&o3);
  EXPECT_EQ(o3.far_depth_baselines, 35.0);
  EXPECT_EQ(o3.far_disparity_sigma_px, 5.0);
  EXPECT_NO_THROW(o3.Check());
  o3.far_depth_baselines = -1;
  EXPECT_THROW(o3.Check(), ConfigError);
  o3.far_depth_baselines = 35;
  o3.far_disparity_sigma_px = 0;
  EXPECT_THROW(o3.Check(), ConfigError);
  auto reader4 = OptionsReader::FromString(
      "motion_prior_sigma_m: 0.05\nmotion_prior_sigma_rad: 0.01\n", "t");
  BundleAdjustmentOptions o4;
  reader4.LoadInto(&o4);
  EXPECT_EQ(o4.motion_prior_sigma_m, 0.05);
  EXPECT_EQ(o4.motion_prior_sigma_rad, 0.01);
  EXPECT_NO_THROW(o4.Check());
  o4.motion_prior_sigma_rad = 0;  // one of the two alone is a mistake, not "off"
  EXPECT_THROW(o4.Check(), ConfigError);
  o4.motion_prior_sigma_m = 0;
  EXPECT_NO_THROW(o4.Check());
  o4.motion_prior_sigma_m = -0.05;
  EXPECT_THROW(o4.Check(), ConfigError);
}

// Moving bodies seen by few points (8) with 1 px noise, outdoors (12–20 m away and receding):
// each frame's body pose rests on a handful of noisy disparities.
BodySceneSpec FewPointBodies() {
  BodySceneSpec spec;
  spec.outdoor = true;
  spec.points_per_body = 8;
  spec.pixel_sigma = 1.0;
  spec.seed = 3;
  return spec;
}

TEST(BundleAdjustment, MotionPriorSteadiesABodySeenByFewNoisyPoints) {
  const BodyScene scene = MakeBodyScene(FewPointBodies());
  const MotionEstimate start = Initialise(scene);
  BundleAdjustmentOptions without;
  BundleAdjustmentOptions with = without;
  with.motion_prior_sigma_m = 0.05;  // the physical a-priori values (docs/backend.md)
  with.motion_prior_sigma_rad = 0.01;
  MotionEstimate a = start, b = start;
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, without, &a).usable);
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, with, &b).usable);
  for (int body = 1; body <= 2; ++body) {
    const double step_without = testing::CentroidStepError(scene, a, body, body),
               step_with = testing::CentroidStepError(scene, b, body, body);
    const double track_without = testing::CentroidTrackScatter(scene, a, body);
    const double track_with = testing::CentroidTrackScatter(scene, b, body);
    std::printf("body %d: step error %.4f -> %.4f m, track scatter %.4f -> %.4f m\n", body,
                step_without, step_with, track_without, track_with);
    // Frame-to-frame jitter is what the prior removes; a slow drift of a receding body's few
    // depths (body 2: 20 → 44 m) it cannot see, but it must not add to it.
    EXPECT_LT(step_with, 0.5 * step_without) << "body " << body;
    EXPECT_LT(track_with, track_without) << "body " << body;
  }
  // The camera comes from the static solve, which the prior does not touch.
  EXPECT_EQ(Ate(a.world_from_cam, scene.world_from_cam), Ate(b.world_from_cam, scene.world_from_cam));
}

TEST(BundleAdjustment, MotionPriorLeavesAConstantVelocityBodyOnItsTrueTrack) {
  // The bodies move at constant velocity and spin: the prior's residual is zero on the truth,
  // so with exact observations the adjustment still ends on it.
  BodySceneSpec spec = FewPointBodies();
  spec.pixel_sigma = 1e-6;
  const BodyScene scene = MakeBodyScene(spec);
  MotionEstimate est = Initialise(scene);
  BundleAdjustmentOptions o;
  o.motion_prior_sigma_m = 0.05;
  o.motion_prior_sigma_rad = 0.01;
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, o, &est).usable);
  for (int body = 1; body <= 2; ++body)
    EXPECT_LT(testing::CentroidTrackRmse(scene, est, body), 1e-4) << "body " << body;
}

TEST(BundleAdjustment, MotionPriorGivesTheSameSolutionOnBothSolvers) {
  const BodyScene scene = MakeBodyScene(FewPointBodies());
  BundleAdjustmentOptions native;
  native.motion_prior_sigma_m = 0.05;
  native.motion_prior_sigma_rad = 0.01;
  native.max_iterations = 200;  // converged tightly, so that the solvers' paths do not matter
  native.function_tolerance = 1e-12;
  BundleAdjustmentOptions ceres = native;
  ceres.native_dense_solver = false;
  BundleAdjustmentOptions profile = native;  // the large-problem path: every solve is "large"
  profile.sparse_schur_min_poses = 0;
  profile.native_sparse_solver = true;
  MotionEstimate a = Initialise(scene), b = a, c = a;
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, native, &a).usable);
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, ceres, &b).usable);
  ASSERT_TRUE(AdjustBundle(scene.table, scene.camera, profile, &c).usable);
  for (int body = 1; body <= 2; ++body) {
    const ClusterMotion* ma = a.FindCluster(body);
    const ClusterMotion* mb = b.FindCluster(body);
    const ClusterMotion* mc = c.FindCluster(body);
    ASSERT_TRUE(ma && mb && mc);
    for (size_t k = 0; k < ma->frames.size(); ++k) {
      EXPECT_LT((ma->world_from_cluster[k].translation() - mb->world_from_cluster[k].translation()).norm(), 1e-4);
      EXPECT_LT((ma->world_from_cluster[k].translation() - mc->world_from_cluster[k].translation()).norm(), 1e-4);
    }
  }
}

}  // namespace
}  // namespace cslam
