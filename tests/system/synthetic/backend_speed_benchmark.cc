// The ClusterSLAM backend on the generator's sequences (the batch and window speed targets,
// docs/benchmarks.md):
//  - BM_EstimateMotionsTrueLabels: one estimation (shape initialisation + decoupled bundle
//    adjustment) over the first N frames with the ground-truth labels — the unit of work the
//    outer loop repeats — with the default options or a solver variant (function tolerance,
//    iterative Schur, dense Schur, Eigen's sparse Cholesky, 10 LM iterations);
//  - BM_ClusterSlamBatch: the whole RunClusterSlam loop over the first N frames;
//  - BM_ClusterSlamWindow: RunClusterSlam on 30-frame windows (the online mode's default
//    window) every 5 frames of the outdoor sequence, reporting the median.
// Counters: LM iterations, final χ², clustering accuracy, so a faster version that changes the
// result shows it. Wall time; on the shared machine compare instruction counts too
// (perf stat -e instructions ./cslam_backend_speed_benchmark --benchmark_filter=...).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "backend/bundle_adjustment.h"
#include "backend/clusterslam.h"
#include "backend/motion_estimation.h"
#include "core/timer.h"
#include "system/eval/clustering_metrics.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {
namespace {

const SyntheticSequence& Sequence(const std::string& preset, int frames) {
  static std::map<std::string, SyntheticSequence> cache;
  const std::string key = preset + std::to_string(frames);
  auto it = cache.find(key);
  if (it == cache.end()) {
    SyntheticOptions o;
    o.preset = preset;
    o.seed = 1;
    o.frames = frames;
    it = cache.emplace(key, GenerateSynthetic(o)).first;
  }
  return it->second;
}

double Accuracy(const SyntheticSequence& seq, FrameRange range, const std::vector<int>& labels) {
  std::vector<int> truth, predicted;
  for (int l : seq.observations.LandmarksIn(range, 4)) {
    truth.push_back(seq.landmark_object[l]);
    predicted.push_back(l < static_cast<int>(labels.size()) ? labels[l] : -1);
  }
  return ClusteringAccuracy(truth, predicted);
}

/// RMS camera position error against the generator's truth; both trajectories start at the
/// identity (world = the camera at frame 0), so no alignment.
double CameraRmse(const SyntheticSequence& seq, const MotionEstimate& est) {
  double sum = 0.0;
  for (size_t f = 0; f < est.world_from_cam.size(); ++f)
    sum += (est.world_from_cam[f].translation() - seq.world_from_cam[f].translation())
               .squaredNorm();
  return est.world_from_cam.empty() ? 0.0 : std::sqrt(sum / est.world_from_cam.size());
}

/// Solver variants of BM_EstimateMotionsTrueLabels (third argument).
MotionEstimationOptions Variant(int variant) {
  MotionEstimationOptions o;
  BundleAdjustmentOptions& ba = o.bundle_adjustment;
  switch (variant) {
    case 1:  // stop when an LM step lowers the cost by less than 1e-4 relative
      ba.function_tolerance = 1e-4;
      break;
    case 2:
      ba.sparse_solver = SparseSolver::kIterativeSchur;
      break;
    case 3:  // DENSE_SCHUR for every solve
      ba.sparse_schur_min_poses = 1 << 30;
      break;
    case 4:
      ba.sparse_library = SparseLibrary::kEigen;
      break;
    case 5:  // the outer loop's intermediate_ba_iterations: 10
      ba.max_iterations = 10;
      break;
    default:
      break;
  }
  return o;
}

// Args: frames, outdoor (1) / indoor (0), solver variant (Variant; 0 = defaults). The shape
// initialisation is timed too; the counters are the adjustment's LM iterations (all solves)
// and the camera's RMS error against the truth, so a faster variant that is less accurate
// shows it.
void BM_EstimateMotionsTrueLabels(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  const SyntheticSequence& seq = Sequence(state.range(1) ? "outdoor" : "indoor", frames);
  const FrameRange range{0, frames};
  const MotionEstimationOptions options = Variant(static_cast<int>(state.range(2)));
  MotionEstimationOptions init = options;
  init.run_bundle_adjustment = false;
  MotionEstimate est;
  BundleAdjustmentSummary summary;
  for (auto _ : state) {
    est = EstimateMotions(seq.observations, seq.camera, range, seq.landmark_object, init);
    summary = AdjustBundle(seq.observations, seq.camera, options.bundle_adjustment, &est);
    // A pointer, not the double: DoNotOptimize(double&) may bind it to an integer register
    // and hand back garbage (this benchmark reported chi2 = 0).
    benchmark::DoNotOptimize(est.world_from_cam.data());
  }
  state.counters["observations"] = est.num_residuals;
  state.counters["chi2"] = est.chi2;
  state.counters["lm_iterations"] = summary.iterations;
  state.counters["camera_rmse_m"] = CameraRmse(seq, est);
}
BENCHMARK(BM_EstimateMotionsTrueLabels)
    ->Args({200, 1, 0})
    ->Args({200, 1, 1})
    ->Args({200, 1, 2})
    ->Args({200, 1, 3})
    ->Args({200, 1, 4})
    ->Args({200, 1, 5})
    ->Args({100, 1, 0})
    ->Args({100, 0, 0})
    ->Args({30, 1, 0})
    ->ArgNames({"frames", "outdoor", "variant"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

void BM_ClusterSlamBatch(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  const bool outdoor = state.range(1) != 0;
  const SyntheticSequence& seq = Sequence(outdoor ? "outdoor" : "indoor", frames);
  const FrameRange range{0, frames};
  const ClusterSlamOptions options =
      outdoor ? ClusterSlamOptions::Outdoor() : ClusterSlamOptions::Indoor();
  BackendResult r;
  for (auto _ : state) {
    r = RunClusterSlam(seq.observations, seq.camera, range, options);
    benchmark::DoNotOptimize(r.estimate.world_from_cam.data());
  }
  state.counters["iterations"] = static_cast<double>(r.iterations.size());
  state.counters["accuracy"] = Accuracy(seq, range, r.estimate.landmark_cluster);
  state.counters["chi2"] = r.estimate.chi2;
}
BENCHMARK(BM_ClusterSlamBatch)
    ->Args({200, 1})
    ->Args({100, 1})
    ->Args({100, 0})
    ->ArgNames({"frames", "outdoor"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Windows [s, s + 30) for s = 0, 5, …, up to `frames`; reports the median window.
void BM_ClusterSlamWindow(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  const SyntheticSequence& seq = Sequence("outdoor", frames);
  const ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
  std::vector<double> ms;
  double accuracy_sum = 0;
  for (auto _ : state) {
    ms.clear();
    accuracy_sum = 0;
    for (int s = 0; s + 30 <= frames; s += 5) {
      const FrameRange range{s, s + 30};
      const Timer timer;
      const BackendResult r = RunClusterSlam(seq.observations, seq.camera, range, options);
      ms.push_back(timer.ElapsedMs());
      accuracy_sum += Accuracy(seq, range, r.estimate.landmark_cluster);
    }
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  state.counters["windows"] = static_cast<double>(ms.size());
  state.counters["median_ms"] = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  state.counters["max_ms"] = sorted.empty() ? 0.0 : sorted.back();
  state.counters["mean_accuracy"] = ms.empty() ? 0.0 : accuracy_sum / ms.size();
}
BENCHMARK(BM_ClusterSlamWindow)
    ->Arg(200)
    ->ArgNames({"frames"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace cslam
