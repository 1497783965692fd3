// Per-frame time of the stereo frontend over the first 50 frames of KITTI raw drive 0005
// (1242×375), on one core: cv::setNumThreads(1). Reports the median ms per frame of each stage,
// wall-clock (wall_*) and thread CPU (cpu_*): on a shared machine the wall clock also counts
// the time the thread waited for the core.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <vector>

#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "tests/frontend/kitti_images.h"

namespace cslam {
namespace {

constexpr int kFrames = 50;

void BM_FrontendDrive0005(benchmark::State& state) {
  cv::setNumThreads(1);
  std::vector<testing::StereoPair> pairs;
  for (int i = 0; i < kFrames; ++i) {
    pairs.push_back(testing::LoadDrive0005Pair(i));
    if (pairs.back().left.empty() || pairs.back().right.empty()) {
      state.SkipWithError("KITTI drive 0005 images not found (set CSLAM_SHARED_DATA)");
      return;
    }
  }
  std::vector<FrameSummary> summaries;
  for (auto _ : state) {
    TrackletTable table;
    StereoFrontend frontend(testing::Drive0005Camera(), FrontendOptions{});
    for (int i = 0; i < kFrames; ++i)
      summaries.push_back(frontend.Process(i, pairs[i].left, pairs[i].right, &table));
    benchmark::DoNotOptimize(table.num_observations());
  }
  const auto median = [&](auto field) {
    std::vector<double> v;
    for (const FrameSummary& s : summaries) v.push_back(field(s));
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  using S = const FrameSummary&;
  state.counters["frames"] = static_cast<double>(summaries.size());
  state.counters["wall_track_ms"] = median([](S s) { return s.track_ms; });
  state.counters["wall_detect_ms"] = median([](S s) { return s.detect_ms; });
  state.counters["wall_stereo_ms"] = median([](S s) { return s.stereo_ms; });
  state.counters["wall_cov_ms"] = median([](S s) { return s.covariance_ms; });
  state.counters["wall_total_ms"] = median([](S s) { return s.total_ms; });
  state.counters["cpu_track_ms"] = median([](S s) { return s.cpu_track_ms; });
  state.counters["cpu_detect_ms"] = median([](S s) { return s.cpu_detect_ms; });
  state.counters["cpu_stereo_ms"] = median([](S s) { return s.cpu_stereo_ms; });
  state.counters["cpu_cov_ms"] = median([](S s) { return s.cpu_covariance_ms; });
  state.counters["cpu_total_ms"] = median([](S s) { return s.cpu_total_ms; });
  state.counters["fps_wall"] = 1000.0 / std::max(1e-9, median([](S s) { return s.total_ms; }));
  state.counters["fps_cpu"] = 1000.0 / std::max(1e-9, median([](S s) { return s.cpu_total_ms; }));
  state.counters["tracked_median"] = median([](S s) { return s.tracked; });
  state.counters["created_median"] = median([](S s) { return s.created; });
}
BENCHMARK(BM_FrontendDrive0005)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace cslam
