#include "system/eval/trajectory_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/support/matchers.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

Pose MakePose(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& translation) {
  Vector6d xi;
  xi << rotation_vector, translation;
  return PoseFromVector(xi);
}

Trajectory FromPoses(const std::vector<Pose>& poses) {
  Trajectory t;
  t.poses = poses;
  for (size_t k = 0; k < poses.size(); ++k) t.frames.push_back(int(k));
  return t;
}

// A curvy ground truth: a car-like path with varying heading and some height.
Trajectory CurvyGroundTruth(int n) {
  std::vector<Pose> poses;
  for (int k = 0; k < n; ++k) {
    const double s = 0.1 * k;
    poses.push_back(MakePose({0.05 * std::sin(s), 0.3 * s, 0.02 * std::cos(2 * s)},
                             {5 * std::sin(0.3 * s), 0.2 * std::sin(s), 3 * s}));
  }
  return FromPoses(poses);
}

// Composes `steps` from the identity: pose_k = pose_{k-1} * step.
Trajectory Integrate(const Pose& step, int n) {
  std::vector<Pose> poses = {Pose::Identity()};
  for (int k = 1; k < n; ++k) poses.push_back(poses.back() * step);
  return FromPoses(poses);
}

Trajectory LeftMultiplied(const Pose& t, const Trajectory& in) {
  Trajectory out = in;
  for (Pose& p : out.poses) p = t * p;
  return out;
}

TEST(Ate, ZeroForAKnownRigidTransformAndRecoversIt) {
  const Trajectory gt = CurvyGroundTruth(60);
  const Pose est_from_gt = MakePose({0.4, -1.1, 0.3}, {10, -3, 7});
  const Trajectory est = LeftMultiplied(est_from_gt, gt);
  const AteResult ate = ComputeAte(gt, est);
  EXPECT_EQ(ate.count, 60u);
  EXPECT_LT(ate.rmse_m, 1e-9);
  EXPECT_LT(ate.max_m, 1e-9);
  EXPECT_NEAR(ate.alignment.scale, 1.0, 1e-12);
  EXPECT_TRUE(testing::PoseNear(ate.alignment.rigid, est_from_gt.inverse(), 1e-9, 1e-8));
}

TEST(Ate, KnownErrorThatNoAlignmentCanRemove) {
  // Square corners (±1, ±1, 0) with est lifted by +h / −h in a twist pattern: the twist has no
  // covariance with the corners, so the best alignment is the identity and every pose is off
  // by exactly h. Repeated (and moved rigidly) it must still give ATE = h.
  const double h = 0.25;
  const Eigen::Vector3d corners[4] = {{1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}};
  const double lift[4] = {h, h, -h, -h};
  std::vector<Pose> gt_poses, est_poses;
  for (int k = 0; k < 40; ++k) {
    Pose g = Pose::Identity(), e = Pose::Identity();
    g.translation() = corners[k % 4];
    e.translation() = corners[k % 4] + Eigen::Vector3d(0, 0, lift[k % 4]);
    gt_poses.push_back(g);
    est_poses.push_back(e);
  }
  const Trajectory gt = FromPoses(gt_poses);
  const Trajectory est =
      LeftMultiplied(MakePose({-0.2, 0.5, 2.0}, {3, 4, 5}), FromPoses(est_poses));
  const AteResult ate = ComputeAte(gt, est);
  EXPECT_NEAR(ate.rmse_m, h, 1e-9);
  EXPECT_NEAR(ate.mean_m, h, 1e-9);
  EXPECT_NEAR(ate.median_m, h, 1e-9);
  EXPECT_NEAR(ate.max_m, h, 1e-9);
}

TEST(Ate, RmseIsMinimalOverAlignments) {
  // Umeyama is the least-squares optimum: any small change of the alignment raises the RMSE.
  const Trajectory gt = CurvyGroundTruth(50);
  Trajectory est = LeftMultiplied(MakePose({0.1, 0.2, -0.3}, {1, 2, 3}), gt);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (Pose& p : est.poses) p.translation() += testing::Draw3([&] { return noise(rng); });
  const AteResult ate = ComputeAte(gt, est);
  ASSERT_GT(ate.rmse_m, 0.1);
  for (int axis = 0; axis < 6; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Vector6d xi = Vector6d::Zero();
      xi(axis) = sign * 1e-3;
      const Pose perturbed = PoseFromVector(xi) * ate.alignment.rigid;
      double sq = 0;
      for (size_t k = 0; k < gt.size(); ++k)
        sq += (gt.poses[k].translation() - perturbed * est.poses[k].translation()).squaredNorm();
      EXPECT_GT(std::sqrt(sq / double(gt.size())), ate.rmse_m);
    }
  }
}

TEST(Ate, Sim3RecoversAKnownScale) {
  // est positions = 0.5 R p + t (est rotations R Q): gt = 2 R⁻¹ (est − t).
  const Trajectory gt = CurvyGroundTruth(40);
  const Pose r = MakePose({0.3, 0.1, -0.7}, {2, -1, 4});
  Trajectory est = gt;
  for (size_t k = 0; k < gt.size(); ++k) {
    est.poses[k].linear() = r.linear() * gt.poses[k].linear();
    est.poses[k].translation() = 0.5 * (r.linear() * gt.poses[k].translation()) + r.translation();
  }
  const AteResult sim3 = ComputeAte(gt, est, /*with_scale=*/true);
  EXPECT_NEAR(sim3.alignment.scale, 2.0, 1e-9);
  EXPECT_LT(sim3.rmse_m, 1e-8);
  const AteResult se3 = ComputeAte(gt, est, /*with_scale=*/false);
  EXPECT_GT(se3.rmse_m, 1.0);  // a 2x scale error over ~12 m of path cannot be aligned away
  const Trajectory aligned = ApplySim3(sim3.alignment, est);
  for (size_t k = 0; k < gt.size(); ++k)
    EXPECT_TRUE(testing::PoseNear(aligned.poses[k], gt.poses[k], 1e-9, 1e-8));
}

TEST(Ate, TooFewPosesGivesNaN) {
  const Trajectory gt = CurvyGroundTruth(2);
  const AteResult ate = ComputeAte(gt, gt);
  EXPECT_EQ(ate.count, 2u);
  EXPECT_TRUE(std::isnan(ate.rmse_m));
}

TEST(RpePerFrame, ZeroUnderAGlobalRigidTransform) {
  const Trajectory gt = CurvyGroundTruth(30);
  const Trajectory est = LeftMultiplied(MakePose({1.0, -0.5, 0.2}, {-4, 2, 9}), gt);
  const RpeResult rpe = ComputeRpePerFrame(gt, est);
  EXPECT_EQ(rpe.count, 29u);
  EXPECT_EQ(rpe.delta, 1);
  EXPECT_LT(rpe.trans_rmse_m, 1e-9);
  EXPECT_LT(rpe.rot_rmse_rad, 1e-9);
  const RpeResult pairs = ComputeRpeAllPairs(gt, est);
  EXPECT_EQ(pairs.count, 30u * 29u);
  EXPECT_LT(pairs.trans_rmse_m, 1e-8);
  EXPECT_LT(pairs.rot_rmse_rad, 1e-9);
}

TEST(RpePerFrame, KnownPerStepRotationError) {
  // gt steps [I | (0,0,1)], est steps [Ry(θ) | (0,0,1)]: E = [I | −z] [Ry(θ) | z] = [Ry(θ) | 0],
  // so every pair has rotation error θ and no translation error.
  const double theta = 0.02;
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), 20);
  const Trajectory est = Integrate(MakePose({0, theta, 0}, {0, 0, 1}), 20);
  const RpeResult rpe = ComputeRpePerFrame(gt, est);
  EXPECT_EQ(rpe.count, 19u);
  EXPECT_NEAR(rpe.rot_rmse_rad, theta, 1e-12);
  EXPECT_NEAR(rpe.rot_mean_rad, theta, 1e-12);
  EXPECT_NEAR(rpe.trans_rmse_m, 0.0, 1e-12);
}

TEST(RpePerFrame, HandComputedSinglePair) {
  // Q0 = I, Q1 = [Rz(90°) | (1,0,0)], P0 = I, P1 = [I | (1,1,0)], all moved by gauge transforms.
  // E = Q1⁻¹ P1 = [Rz(−90°) | Rz(−90°)((1,1,0) − (1,0,0))] = [Rz(−90°) | (1,0,0)]:
  // translation 1 m, rotation π/2.
  const Pose q1 = MakePose({0, 0, M_PI / 2}, {1, 0, 0});
  const Pose p1 = MakePose({0, 0, 0}, {1, 1, 0});
  const Trajectory gt =
      LeftMultiplied(MakePose({0.3, 0.2, 0.1}, {5, 5, 5}), FromPoses({Pose::Identity(), q1}));
  const Trajectory est =
      LeftMultiplied(MakePose({-1, 0.4, 2}, {-3, 1, 0}), FromPoses({Pose::Identity(), p1}));
  const RpeResult rpe = ComputeRpePerFrame(gt, est);
  EXPECT_EQ(rpe.count, 1u);
  EXPECT_NEAR(rpe.trans_rmse_m, 1.0, 1e-12);
  EXPECT_NEAR(rpe.rot_rmse_rad, M_PI / 2, 1e-12);
}

TEST(RpePerFrame, ErrorIsExpressedInTheLocalFrame) {
  // A turning car (gt steps [Ry(φ) | (0,0,1)]) whose estimate overshoots each step by ε along its
  // own forward axis: E = [I | (0,0,ε)] for every pair.
  const double phi = 0.1, eps = 0.03;
  const Trajectory gt = Integrate(MakePose({0, phi, 0}, {0, 0, 1}), 15);
  const Trajectory est = Integrate(MakePose({0, phi, 0}, {0, 0, 1 + eps}), 15);
  const RpeResult rpe = ComputeRpePerFrame(gt, est);
  EXPECT_NEAR(rpe.trans_rmse_m, eps, 1e-12);
  EXPECT_NEAR(rpe.rot_rmse_rad, 0.0, 1e-12);
}

TEST(RpePerFrame, OneDisplacedPose) {
  // Identity rotations, pose 0 displaced by d: E_ij = δ_j − δ_i. Per frame only pair (0,1)
  // sees it: RMSE d/√(n−1), mean d/(n−1). All pairs: 2(n−1) of n(n−1) pairs: RMSE d√(2/n).
  const int n = 10;
  const double d = 0.4;
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), n);
  Trajectory est = gt;
  est.poses[0].translation() += Eigen::Vector3d(d, 0, 0);
  const RpeResult frame = ComputeRpePerFrame(gt, est);
  EXPECT_NEAR(frame.trans_rmse_m, d / std::sqrt(n - 1.0), 1e-12);
  EXPECT_NEAR(frame.trans_mean_m, d / (n - 1.0), 1e-12);
  const RpeResult pairs = ComputeRpeAllPairs(gt, est);
  EXPECT_EQ(pairs.count, size_t(n * (n - 1)));
  EXPECT_EQ(pairs.delta, 0);
  EXPECT_NEAR(pairs.trans_rmse_m, d * std::sqrt(2.0 / n), 1e-12);
  EXPECT_NEAR(pairs.trans_mean_m, d * 2.0 / n, 1e-12);
}

TEST(RpePerFrame, DeltaUsesEvoNonOverlappingPairs) {
  // evo (delta 2, not all_pairs): pairs (0,2), (2,4) of 6 poses.
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), 6);
  Trajectory est = gt;
  est.poses[5].translation() += Eigen::Vector3d(1, 0, 0);  // pose 5 is in no pair
  const RpeResult rpe = ComputeRpePerFrame(gt, est, 2);
  EXPECT_EQ(rpe.count, 2u);
  EXPECT_EQ(rpe.delta, 2);
  EXPECT_NEAR(rpe.trans_rmse_m, 0.0, 1e-12);
  est.poses[4].translation() += Eigen::Vector3d(1, 0, 0);  // in pair (2,4) only
  EXPECT_NEAR(ComputeRpePerFrame(gt, est, 2).trans_rmse_m, std::sqrt(0.5), 1e-12);
}

TEST(RpeAllPairs, SubsamplesReproduciblyAndEstimatesTheFullValue) {
  const int n = 200;  // 39 800 ordered pairs > 10 000
  const double d = 1.0;
  const Trajectory gt = Integrate(MakePose({0, 0.01, 0}, {0, 0, 1}), n);
  Trajectory est = gt;
  for (int k = 0; k < n; k += 5) est.poses[size_t(k)].translation() += Eigen::Vector3d(0, d, 0);
  const RpeResult a = ComputeRpeAllPairs(gt, est, 10000, 42);
  const RpeResult b = ComputeRpeAllPairs(gt, est, 10000, 42);
  const RpeResult c = ComputeRpeAllPairs(gt, est, 10000, 7);
  EXPECT_EQ(a.count, 10000u);
  EXPECT_EQ(a.trans_rmse_m, b.trans_rmse_m);
  EXPECT_NE(a.trans_rmse_m, c.trans_rmse_m);
  // Exact: a pair has error d when exactly one of its poses is displaced (1 in 5 are):
  // fraction 2 * (1/5) * (4/5) * n/(n−1) of ordered pairs i ≠ j.
  const double fraction = 2.0 * 40 * 160 / (double(n) * (n - 1));
  EXPECT_NEAR(a.trans_rmse_m, d * std::sqrt(fraction), 0.05 * d * std::sqrt(fraction));
}

TEST(KittiSegments, HandComputedScaleError) {
  // Straight 300 m, 1 m per frame, estimate 1 % too long. The devkit's last frame is the first
  // whose distance exceeds the start's by MORE than the length: 101 m for 100, 201 m for 200.
  // Starts 0, 10, ..., 190 have a 100 m segment (20), starts 0..90 a 200 m one (10), none 300.
  // t_err/len = 0.01 * 101/100 resp. 0.01 * 201/200 → t_rel = (20*1.01 + 10*1.005)/30 %.
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), 301);
  const Trajectory est = Integrate(MakePose({0, 0, 0}, {0, 0, 1.01}), 301);
  const KittiSegmentError e = ComputeKittiSegmentErrors(gt, est);
  EXPECT_TRUE(e.defined);
  EXPECT_EQ(e.segments, 30u);
  EXPECT_NEAR(e.t_rel_percent, (20 * 1.01 + 10 * 1.005) / 30.0, 1e-9);
  EXPECT_NEAR(e.r_rel_deg_per_m, 0.0, 1e-12);
}

TEST(KittiSegments, HandComputedRotationDrift) {
  // est heading drifts by β per frame on gt's positions: the error angle of a segment of m
  // frames is m β, so r_rel = (180/π) β (20 * 101/100 + 10 * 201/200) / 30 deg/m.
  const double beta = 1e-3;
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), 301);
  Trajectory est = gt;
  for (size_t k = 0; k < est.size(); ++k)
    est.poses[k].linear() = ExpSO3(Eigen::Vector3d(0, beta * double(k), 0));
  const KittiSegmentError e = ComputeKittiSegmentErrors(gt, est);
  ASSERT_TRUE(e.defined);
  EXPECT_NEAR(e.r_rel_deg_per_m, (180.0 / M_PI) * beta * (20 * 1.01 + 10 * 1.005) / 30.0, 1e-9);
}

TEST(KittiSegments, UndefinedBelow100Metres) {
  const Trajectory gt = Integrate(MakePose({0, 0, 0}, {0, 0, 1}), 70);  // 69 m, like drive 0005
  const KittiSegmentError e = ComputeKittiSegmentErrors(gt, gt);
  EXPECT_FALSE(e.defined);
  EXPECT_EQ(e.segments, 0u);
  EXPECT_TRUE(std::isnan(e.t_rel_percent));
}

TEST(PathLength, SumsConsecutiveDistances) {
  EXPECT_NEAR(PathLength(Integrate(MakePose({0, 0.3, 0}, {0, 3, 4}), 11)), 50.0, 1e-12);
  EXPECT_EQ(PathLength(Trajectory{}), 0.0);
}

TEST(Associate, ByFrameIndex) {
  Trajectory gt = Integrate(MakePose({0, 0, 0}, {1, 0, 0}), 10);
  Trajectory est;
  est.frames = {2, 5, 7, 12};
  for (int f : est.frames) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(f, 0, 0);
    est.poses.push_back(p);
  }
  const TrajectoryAssociation a = Associate(gt, est);
  EXPECT_EQ(a.gt, (std::vector<size_t>{2, 5, 7}));
  EXPECT_EQ(a.est, (std::vector<size_t>{0, 1, 2}));
  EXPECT_LT(ComputeAte(gt, est).rmse_m, 1e-12);
  EXPECT_EQ(ComputeAte(gt, est).count, 3u);
}

TEST(Associate, ByNearestTimestampWithinTolerance) {
  // gt at 0.0, 0.1, ..., 0.9; est shifted by +4 ms except one 30 ms off (dropped), and a
  // shorter est snaps onto gt (evo's rule).
  Trajectory gt = Integrate(MakePose({0, 0, 0}, {1, 0, 0}), 10);
  gt.frames.clear();
  for (int k = 0; k < 10; ++k) gt.timestamps.push_back(0.1 * k);
  Trajectory est;
  est.timestamps = {0.104, 0.304, 0.53, 0.704, 0.896};
  est.poses.assign(est.timestamps.size(), Pose::Identity());
  const TrajectoryAssociation a = Associate(gt, est);
  EXPECT_EQ(a.gt, (std::vector<size_t>{1, 3, 7, 9}));
  EXPECT_EQ(a.est, (std::vector<size_t>{0, 1, 3, 4}));
  // Longer est: each gt pose takes its nearest est pose.
  const TrajectoryAssociation b = Associate(est, gt);
  EXPECT_EQ(b.gt, (std::vector<size_t>{0, 1, 3, 4}));
  EXPECT_EQ(b.est, (std::vector<size_t>{1, 3, 7, 9}));
  AssociationOptions loose;
  loose.max_time_difference_s = 0.05;
  EXPECT_EQ(Associate(gt, est, loose).size(), 5u);
}

}  // namespace
}  // namespace cslam
