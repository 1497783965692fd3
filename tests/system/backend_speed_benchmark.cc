// The ClusterSLAM backend on the generator's sequences (issues 3 and 5 speed targets):
//  - BM_EstimateMotionsTrueLabels: one EstimateMotions call (shape initialisation + decoupled
//    bundle adjustment, default options) over the first N frames with the ground-truth labels
//    — the unit of work the outer loop repeats;
//  - BM_ClusterSlamBatch: the whole RunClusterSlam loop over the first N frames;
//  - BM_ClusterSlamWindow: RunClusterSlam on 30-frame windows (the online mode's default
//    window) every 5 frames of the outdoor sequence, reporting the median.
// Counters: LM iterations, final χ², clustering accuracy, so a faster version that changes the
// result shows it. Wall time; on the shared machine compare instruction counts too
// (perf stat -e instructions ./cslam_backend_speed_benchmark --benchmark_filter=...).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "backend/bundle_adjustment.h"
#include "backend/clusterslam.h"
#include "backend/motion_estimation.h"
#include "core/timer.h"
#include "system/clustering_metrics.h"
#include "system/synthetic_scene.h"

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

// Args: frames, outdoor (1) / indoor (0).
void BM_EstimateMotionsTrueLabels(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  const SyntheticSequence& seq = Sequence(state.range(1) ? "outdoor" : "indoor", frames);
  const FrameRange range{0, frames};
  const MotionEstimationOptions options;
  MotionEstimate est;
  for (auto _ : state) {
    est = EstimateMotions(seq.observations, seq.camera, range, seq.landmark_object, options);
    benchmark::DoNotOptimize(est.chi2);
  }
  state.counters["observations"] = est.num_residuals;
  state.counters["chi2"] = est.chi2;
}
BENCHMARK(BM_EstimateMotionsTrueLabels)
    ->Args({200, 1})
    ->Args({100, 1})
    ->Args({100, 0})
    ->Args({30, 1})
    ->ArgNames({"frames", "outdoor"})
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
    benchmark::DoNotOptimize(r.estimate.chi2);
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
