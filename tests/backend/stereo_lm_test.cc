#include "backend/stereo_lm.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <random>
#include <vector>

#include "core/stereo_camera.h"

namespace cslam {
namespace {

/// A camera moving forward past points 5–40 m ahead, every point seen in every frame; the
/// measurements are the exact projections (plus `sigma_px` Gaussian noise).
struct Scene {
  StereoCamera camera{718.856, 718.856, 607.19, 185.22, 0.537};
  std::vector<std::array<double, 7>> true_poses, poses;  // cam_from_world
  std::vector<std::array<double, 3>> true_points, points;
  StereoLmProblem problem;
};

std::array<double, 7> Block(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

Scene MakeScene(int frames, int num_points, double sigma_px, unsigned seed) {
  Scene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.02 * f, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d world_t_cam(0.1 * f, 0.0, 1.0 * f);
    s.true_poses.push_back(Block(q.conjugate(), -(q.conjugate() * world_t_cam)));
  }
  for (int i = 0; i < num_points; ++i)
    s.true_points.push_back({8.0 * u(rng), 2.0 * u(rng), 5.0 + frames + 35.0 * (0.5 + 0.5 * u(rng))});
  s.poses = s.true_poses;
  s.points = s.true_points;
  const Eigen::Matrix3d sqrt_info = Eigen::Matrix3d::Identity() / std::max(sigma_px, 0.5);
  for (int f = 0; f < frames; ++f)
    for (int i = 0; i < num_points; ++i) {
      const Eigen::Map<const Eigen::Quaterniond> q(s.true_poses[f].data());
      const Eigen::Vector3d p =
          q * Eigen::Vector3d(s.true_points[i].data()) +
          Eigen::Vector3d(s.true_poses[f][4], s.true_poses[f][5], s.true_poses[f][6]);
      Eigen::Vector3d x;
      if (!s.camera.Project(p, &x)) continue;
      x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      s.problem.residuals.push_back({f, i, x, sqrt_info});
    }
  return s;
}

void Bind(Scene* s) {
  s->problem.poses.clear();
  s->problem.points.clear();
  s->problem.pose_free.assign(s->poses.size(), true);
  s->problem.pose_free[0] = false;  // gauge
  for (auto& p : s->poses) s->problem.poses.push_back(p.data());
  for (auto& p : s->points) s->problem.points.push_back(p.data());
}

/// Rotates and shifts every free pose and every point by a few degrees and decimetres.
void Perturb(Scene* s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (size_t f = 1; f < s->poses.size(); ++f) {
    Eigen::Map<Eigen::Quaterniond> q(s->poses[f].data());
    q = Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())) * q;
    for (int j = 4; j < 7; ++j) s->poses[f][j] += 0.2 * u(rng);
  }
  for (auto& p : s->points)
    for (int j = 0; j < 3; ++j) p[j] += 0.3 * u(rng);
}

double MaxPoseError(const Scene& s) {
  double e = 0.0;
  for (size_t f = 0; f < s.poses.size(); ++f) {
    const Eigen::Map<const Eigen::Quaterniond> q(s.poses[f].data()), q0(s.true_poses[f].data());
    e = std::max(e, q.angularDistance(q0));
    for (int j = 4; j < 7; ++j) e = std::max(e, std::abs(s.poses[f][j] - s.true_poses[f][j]));
  }
  return e;
}

TEST(StereoLm, RecoversTheExactSolutionFromAPerturbedStartWithoutNoise) {
  Scene s = MakeScene(10, 120, 0.0, 1);
  Perturb(&s, 2);
  Bind(&s);
  const double before = MaxPoseError(s);
  StereoLmOptions o;
  o.max_iterations = 100;
  o.function_tolerance = 1e-14;
  const StereoLmSummary summary = SolveStereoLm(s.camera, o, &s.problem);
  EXPECT_FALSE(summary.failed);
  EXPECT_GT(summary.successful, 3);
  EXPECT_GT(before, 0.02);
  EXPECT_LT(MaxPoseError(s), 1e-6);
  EXPECT_LT(summary.final_cost, 1e-9 * summary.initial_cost);
  for (size_t i = 0; i < s.points.size(); ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(s.points[i][j], s.true_points[i][j], 1e-5);
}

// 8 points in 20 frames: the solver eliminates the poses instead of the points.
TEST(StereoLm, FewPointsInManyFramesAlsoReachTheExactSolution) {
  Scene s = MakeScene(20, 8, 0.0, 11);
  Perturb(&s, 12);
  Bind(&s);
  StereoLmOptions o;
  o.max_iterations = 200;
  o.function_tolerance = 1e-14;
  const StereoLmSummary summary = SolveStereoLm(s.camera, o, &s.problem);
  EXPECT_FALSE(summary.failed);
  EXPECT_LT(MaxPoseError(s), 1e-6);
  EXPECT_LT(summary.final_cost, 1e-9 * summary.initial_cost);
}

// profile_cholesky: a sequence-like problem where each point is seen in a run of 13 frames
// around its own frame (the reduced camera system is a band), and the few-points problem
// (the points' system): the profile factor gives the dense factor's steps, so both runs reach
// the exact solution and agree with each other.
TEST(StereoLm, ProfileCholeskyReachesTheDenseSolutionOnBandedAndPointSideSystems) {
  struct Case {
    int frames, points, half_run;
  };
  for (const Case c : {Case{40, 400, 6}, Case{20, 8, 100}}) {
    Scene base = MakeScene(c.frames, c.points, 0.0, 21);
    std::vector<StereoLmResidual> kept;
    for (const StereoLmResidual& r : base.problem.residuals)
      if (std::abs(r.pose - r.point % c.frames) <= c.half_run) kept.push_back(r);
    base.problem.residuals = kept;
    Perturb(&base, 22);
    Scene dense = base, profile = base;
    Bind(&dense);
    Bind(&profile);
    StereoLmOptions o;
    o.max_iterations = 200;
    o.function_tolerance = 1e-14;
    const StereoLmSummary sd = SolveStereoLm(dense.camera, o, &dense.problem);
    o.profile_cholesky = true;
    const StereoLmSummary sp = SolveStereoLm(profile.camera, o, &profile.problem);
    EXPECT_FALSE(sp.failed);
    EXPECT_EQ(sp.successful, sd.successful) << c.frames;
    EXPECT_LT(MaxPoseError(profile), 1e-6) << c.frames;
    EXPECT_LT(sp.final_cost, 1e-9 * sp.initial_cost) << c.frames;
    for (size_t f = 0; f < profile.poses.size(); ++f)
      for (int j = 0; j < 7; ++j) EXPECT_NEAR(profile.poses[f][j], dense.poses[f][j], 1e-9);
    for (size_t i = 0; i < profile.points.size(); ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(profile.points[i][j], dense.points[i][j], 1e-7);
  }
}

TEST(StereoLm, HeldPosesStayBitForBitAndNoiseLeavesTheExpectedChi2) {
  const int frames = 8, points = 150;
  Scene s = MakeScene(frames, points, 1.0, 3);
  Perturb(&s, 4);
  Bind(&s);
  s.problem.pose_free[3] = false;
  s.poses[3] = s.true_poses[3];
  const std::array<double, 7> held0 = s.poses[0], held3 = s.poses[3];
  const double before = MaxPoseError(s);
  StereoLmOptions o;
  o.kernel = RobustKernel::kNone;
  o.max_iterations = 100;
  o.function_tolerance = 1e-12;
  const StereoLmSummary summary = SolveStereoLm(s.camera, o, &s.problem);
  EXPECT_EQ(s.poses[0], held0);
  EXPECT_EQ(s.poses[3], held3);
  // At the minimum ½χ² ≈ ½(residuals − unknowns) for unit-variance noise.
  const double dof = 3.0 * s.problem.residuals.size() - 6.0 * (frames - 2) - 3.0 * points;
  EXPECT_NEAR(2.0 * summary.final_cost / dof, 1.0, 0.1);
  EXPECT_LT(MaxPoseError(s), 0.1 * before);
}

TEST(StereoLm, HuberAndDcsKeepGrossOutliersFromPullingThePoses) {
  // Every 10th measurement 40 px off; the reference is the same scene without them.
  auto solve = [](RobustKernel kernel, bool outliers) {
    Scene s = MakeScene(8, 150, 0.5, 5);
    if (outliers)
      for (size_t k = 0; k < s.problem.residuals.size(); k += 10)
        s.problem.residuals[k].x += Eigen::Vector3d(40.0, -25.0, 40.0);
    Perturb(&s, 6);
    Bind(&s);
    StereoLmOptions o;
    o.kernel = kernel;
    o.max_iterations = 100;
    EXPECT_FALSE(SolveStereoLm(s.camera, o, &s.problem).failed);
    return MaxPoseError(s);
  };
  const double clean = solve(RobustKernel::kNone, false);
  const double plain = solve(RobustKernel::kNone, true);
  for (RobustKernel kernel : {RobustKernel::kHuber, RobustKernel::kDcs}) {
    const double robust = solve(kernel, true);
    std::printf("kernel %d: pose error %.4f (no kernel %.4f, no outliers %.4f)\n",
                static_cast<int>(kernel), robust, plain, clean);
    // Huber still gives each outlier a linear pull; DCS's weight falls off with its square.
    EXPECT_LT(robust, (kernel == RobustKernel::kDcs ? 0.3 : 0.5) * plain)
        << static_cast<int>(kernel);
  }
}

TEST(StereoLm, AStartWithAPointBehindACameraFailsWithoutMovingAnything) {
  Scene s = MakeScene(4, 20, 0.0, 7);
  s.points[5] = {0.0, 0.0, -10.0};
  Bind(&s);
  const auto poses = s.poses;
  const StereoLmSummary summary = SolveStereoLm(s.camera, {}, &s.problem);
  EXPECT_TRUE(summary.failed);
  EXPECT_EQ(s.poses, poses);
}

}  // namespace
}  // namespace cslam
