// One decoupled bundle adjustment on an outdoor-like chunk (baseline 0.5 m, points to 60 m,
// 50 frames, 3 moving bodies of 100 points), for 2 000 / 5 000 / 10 000 landmarks and 20
// (the paper's ablation) or 50 (our default) Levenberg–Marquardt iterations per solve, and for
// 5 000 landmarks the other linear solvers (solver: 0 SuiteSparse normal Cholesky, 1 iterative
// Schur, 2 dense Schur, 3 Eigen's sparse Cholesky). Reports wall
// time per solve and the process's peak resident set (getrusage ru_maxrss, which only grows: run
// one size per process with --benchmark_filter for a per-size figure).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include "backend/bundle_adjustment.h"
#include "tests/backend/synthetic_bodies.h"

namespace cslam {
namespace {

void BM_DecoupledBundleAdjustment(benchmark::State& state) {
  testing::BodySceneSpec spec;
  spec.outdoor = true;
  spec.num_frames = 50;
  spec.num_moving = 3;
  spec.points_per_body = 100;
  spec.num_static = static_cast<int>(state.range(0)) - spec.num_moving * spec.points_per_body;
  spec.pixel_sigma = 1.0;
  const testing::BodyScene scene = testing::MakeBodyScene(spec);
  MotionEstimationOptions init;
  init.run_bundle_adjustment = false;
  const MotionEstimate initial =
      EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, init);
  BundleAdjustmentOptions options;  // defaults: decoupled, Huber
  options.max_iterations = static_cast<int>(state.range(1));
  switch (state.range(2)) {  // linear solver of the large (static) solve
    case 1:
      options.sparse_solver = SparseSolver::kIterativeSchur;
      break;
    case 2:
      options.sparse_schur_min_poses = 1 << 30;  // DENSE_SCHUR
      break;
    case 3:
      options.sparse_library = SparseLibrary::kEigen;
      break;
    default:  // SuiteSparse normal Cholesky
      break;
  }
  BundleAdjustmentSummary summary;
  rusage before{};
  getrusage(RUSAGE_SELF, &before);  // scene, table and initial estimate: not the solver's
  for (auto _ : state) {
    state.PauseTiming();
    MotionEstimate est = initial;
    state.ResumeTiming();
    summary = AdjustBundle(scene.table, scene.camera, options, &est);
    benchmark::DoNotOptimize(est.world_from_cam.data());  // a double may come back garbled
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["landmarks"] = static_cast<double>(state.range(0));
  state.counters["observations"] = static_cast<double>(scene.table.num_observations());
  state.counters["lm_iterations"] = summary.iterations;
  state.counters["final_chi2"] = summary.final_chi2;
  state.counters["peak_rss_MB"] = usage.ru_maxrss / 1024.0;
  state.counters["rss_before_ba_MB"] = before.ru_maxrss / 1024.0;
}
BENCHMARK(BM_DecoupledBundleAdjustment)
    ->ArgsProduct({{2000, 5000, 10000}, {20, 50}, {0}})
    ->Args({5000, 50, 1})
    ->Args({5000, 50, 2})
    ->Args({5000, 50, 3})
    ->ArgNames({"landmarks", "max_iterations", "solver"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
}  // namespace cslam
