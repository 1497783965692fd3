// Per-frame time of the stereo frontend over the first 50 frames of KITTI raw drive 0005
// (1242×375), on one core: cv::setNumThreads(1). Reports the median wall-clock ms per stage
// as counters, and the median CPU time of the whole frame (the machine may be shared, so
// wall-clock stages can include time the thread spent waiting for the core).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <opencv2/core/utility.hpp>
#include <vector>

#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "tests/frontend/kitti_images.h"

namespace cslam {
namespace {

constexpr int kFrames = 50;

double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

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
  std::vector<double> track, detect, stereo, cov, total, cpu;
  double tracked = 0, created = 0;
  for (auto _ : state) {
    TrackletTable table;
    StereoFrontend frontend(testing::Drive0005Camera(), FrontendOptions{});
    for (int i = 0; i < kFrames; ++i) {
      const double cpu_start = ThreadCpuMs();
      const FrameSummary s = frontend.Process(i, pairs[i].left, pairs[i].right, &table);
      cpu.push_back(ThreadCpuMs() - cpu_start);
      track.push_back(s.track_ms);
      detect.push_back(s.detect_ms);
      stereo.push_back(s.stereo_ms);
      cov.push_back(s.covariance_ms);
      total.push_back(s.total_ms);
      tracked += s.tracked;
      created += s.created;
    }
    benchmark::DoNotOptimize(table.num_observations());
  }
  const double frames = static_cast<double>(total.size());
  state.counters["frames"] = frames;
  state.counters["median_track_ms"] = Median(track);
  state.counters["median_detect_ms"] = Median(detect);
  state.counters["median_stereo_ms"] = Median(stereo);
  state.counters["median_cov_ms"] = Median(cov);
  state.counters["median_total_ms"] = Median(total);
  state.counters["median_cpu_ms"] = Median(cpu);
  state.counters["fps_at_median"] = 1000.0 / std::max(1e-9, Median(total));
  state.counters["tracked_per_frame"] = tracked / frames;
  state.counters["created_per_frame"] = created / frames;
}
BENCHMARK(BM_FrontendDrive0005)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace cslam
