// The native solver on the shape of an online window's static solve
// (docs/experiments/2026-12-02-warm-window-profile.md): 30 poses, 1 700 points 8–60 m ahead, each
// seen in a run of 6–14 consecutive frames (≈ 17 000 stereo residuals), 1 px noise, a start a few
// centimetres and milliradians off. Fixed LM iteration counts (the function tolerance is out of
// reach), so the time per solve is per-iteration cost × iterations; `lm` is the argument.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <array>
#include <random>
#include <vector>

#include "backend/stereo_lm.h"

namespace cslam {
namespace {

struct WindowProblem {
  StereoCamera camera{718.856, 718.856, 607.19, 185.22, 0.537};
  std::vector<std::array<double, 7>> poses;
  std::vector<std::array<double, 3>> points;
  std::vector<StereoLmResidual> residuals;
};

WindowProblem MakeWindowProblem(int frames, int num_points, unsigned seed) {
  WindowProblem w;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Eigen::Isometry3d> cam_from_world;
  for (int f = 0; f < frames; ++f) {
    Eigen::Isometry3d world_from_cam = Eigen::Isometry3d::Identity();
    world_from_cam.linear() = Eigen::AngleAxisd(0.01 * f, Eigen::Vector3d::UnitY()).toRotationMatrix();
    world_from_cam.translation() = Eigen::Vector3d(0.05 * f, 0.0, 1.0 * f);
    cam_from_world.push_back(world_from_cam.inverse());
    const Eigen::Quaterniond q(cam_from_world.back().linear());
    Eigen::Quaterniond dq(Eigen::AngleAxisd(0.002 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
    const Eigen::Quaterniond start = f == 0 ? q : (dq * q).normalized();
    const Eigen::Vector3d t = cam_from_world.back().translation() +
                              (f == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.03 * u(rng), 0.03 * u(rng), 0.05 * u(rng)));
    w.poses.push_back({start.x(), start.y(), start.z(), start.w(), t.x(), t.y(), t.z()});
  }
  std::uniform_int_distribution<int> length(6, 14);
  for (int i = 0; i < num_points; ++i) {
    const int len = length(rng);
    const int first = std::uniform_int_distribution<int>(0, frames - len)(rng);
    const double depth = 8.0 + 52.0 * (0.5 + 0.5 * u(rng));
    const Eigen::Vector3d in_first(depth * 0.6 * u(rng), 1.5 * u(rng) + 0.5, depth);
    const Eigen::Vector3d world = cam_from_world[first].inverse() * in_first;
    int seen = 0;
    for (int f = first; f < first + len; ++f) {
      Eigen::Vector3d x;
      const Eigen::Vector3d in_cam = cam_from_world[f] * world;
      if (in_cam.z() < 3.0 || !w.camera.Project(in_cam, &x)) continue;
      if (x(0) < 0 || x(0) > 1242 || x(1) < 0 || x(1) > 375) continue;
      x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      w.residuals.push_back({f, i, x, Eigen::Matrix3d::Identity()});
      ++seen;
    }
    const Eigen::Vector3d start = world + Eigen::Vector3d(0.05 * u(rng), 0.05 * u(rng), 0.3 * u(rng));
    w.points.push_back({start.x(), start.y(), start.z()});
    if (seen == 0) w.points.back() = {0, 0, 1e6};  // unobserved: never in a residual
  }
  return w;
}

StereoLmProblem Bind(WindowProblem* w) {
  StereoLmProblem p;
  for (auto& pose : w->poses) p.poses.push_back(pose.data());
  p.pose_free.assign(w->poses.size(), true);
  p.pose_free[0] = false;
  for (auto& point : w->points) p.points.push_back(point.data());
  p.residuals = w->residuals;
  return p;
}

void Run(benchmark::State& state, const WindowProblem& initial, const StereoLmOptions& options) {
  StereoLmSummary summary;
  for (auto _ : state) {
    state.PauseTiming();
    WindowProblem w = initial;
    StereoLmProblem p = Bind(&w);
    state.ResumeTiming();
    summary = SolveStereoLm(w.camera, options, &p);
    benchmark::DoNotOptimize(w.poses.data());
  }
  if (summary.failed) state.SkipWithError("the start could not be evaluated");
  state.counters["residuals"] = static_cast<double>(initial.residuals.size());
  state.counters["lm_iterations"] = summary.iterations;
  state.counters["cost_ratio"] = summary.final_cost / summary.initial_cost;
}

void BM_StereoLmStaticWindow(benchmark::State& state) {
  StereoLmOptions options;
  options.max_iterations = static_cast<int>(state.range(0));
  options.function_tolerance = 1e-15;
  Run(state, MakeWindowProblem(30, 1700, 5), options);
}
BENCHMARK(BM_StereoLmStaticWindow)->ArgName("lm")->Arg(1)->Arg(5)->Unit(benchmark::kMillisecond);

// A window's moving cluster: `points` landmarks of one body over the 30 frames (a moving
// cluster's solve is the same problem in the body's frame), 10 LM iterations, the reduced
// system factored densely (profile 0) or by its profile (1).
void BM_StereoLmMovingCluster(benchmark::State& state) {
  StereoLmOptions options;
  options.max_iterations = 10;
  options.function_tolerance = 1e-15;
  options.profile_cholesky = state.range(1) != 0;
  Run(state, MakeWindowProblem(30, static_cast<int>(state.range(0)), 7), options);
}
BENCHMARK(BM_StereoLmMovingCluster)
    ->ArgNames({"points", "profile"})
    ->ArgsProduct({{15, 60, 200}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cslam
