// Micro-benchmarks of the clustering half of ClusterSLAM on the paper's size (§4.4-B: a
// 260 × 260 motion distance matrix): 260 landmarks on 5 rigid bodies, every landmark seen in
// all 100 frames of the chunk (the densest case: 33 670 pairs × 100 frames).
#include <benchmark/benchmark.h>

#include <random>

#include "backend/hac.h"
#include "backend/motion_distance.h"
#include "backend/point_tracks.h"
#include "tests/backend/test_scene.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

struct Fixture {
  testing::TestScene scene;
  PointTracks tracks;
  FrameRange chunk{0, 100};
};

const Fixture& Dense260() {
  static const Fixture f = [] {
    Fixture fx;
    std::vector<testing::TestBody> bodies(5);
    bodies[0].points_in_body = testing::RandomPoints(140, {-2.5, -1.2, 4}, {2.5, 1.2, 8}, 1);
    bodies[0].world_from_body = [](int) { return Pose::Identity(); };
    for (int b = 1; b < 5; ++b) {
      bodies[b].points_in_body = testing::RandomPoints(30, {-0.4, -0.4, -0.4}, {0.4, 0.4, 0.4}, b + 1);
      bodies[b].world_from_body = [b](int t) {
        return testing::YawPose(0.005 * b * t,
                                Eigen::Vector3d(-1.0 + 0.5 * b, -0.5 + 0.25 * b, 4.0 + 0.01 * b * t));
      };
    }
    fx.scene = testing::MakeScene(testing::SyntheticCamera(false), bodies, 100,
                                  [](int t) { return testing::YawPose(0.001 * t, {0, 0, 0.005 * t}); },
                                  1.0, 1.0, 7);
    fx.tracks = BackProjectTracks(fx.scene.table, fx.scene.camera, fx.chunk);
    return fx;
  }();
  return f;
}

void BM_MotionDistance260x100(benchmark::State& state) {
  const Fixture& f = Dense260();
  size_t pairs = 0;
  for (auto _ : state) {
    const SparseDistances d = ComputeMotionDistances(f.scene.table, f.tracks, f.chunk, {});
    pairs = d.entries.size();
    benchmark::DoNotOptimize(d.entries.data());
  }
  state.counters["landmarks"] = f.scene.table.num_landmarks();
  state.counters["observations"] = static_cast<double>(f.scene.table.num_observations());
  state.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_MotionDistance260x100)->Unit(benchmark::kMillisecond);

void BM_HacDense260(benchmark::State& state) {
  const Fixture& f = Dense260();
  const SparseDistances d = ComputeMotionDistances(f.scene.table, f.tracks, f.chunk, {});
  HacOptions o;
  int clusters = 0;
  for (auto _ : state) {
    const auto labels = CompleteLinkageHac(d, o);
    clusters = *std::max_element(labels.begin(), labels.end()) + 1;
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["entries"] = static_cast<double>(d.entries.size());
  state.counters["clusters"] = clusters;
}
BENCHMARK(BM_HacDense260)->Unit(benchmark::kMicrosecond);

// Worst case for the heap: every entry below ε, so all 33 670 pairs enter it.
void BM_HacDense260AllBelowEpsilon(benchmark::State& state) {
  const Fixture& f = Dense260();
  SparseDistances d = ComputeMotionDistances(f.scene.table, f.tracks, f.chunk, {});
  HacOptions o;
  o.epsilon = 1e300;
  for (auto _ : state) {
    const auto labels = CompleteLinkageHac(d, o);
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["entries"] = static_cast<double>(d.entries.size());
}
BENCHMARK(BM_HacDense260AllBelowEpsilon)->Unit(benchmark::kMicrosecond);

// A long outdoor-like chunk: 3000 landmarks, 200 frames, tracks of 20-60 frames (KLT-like),
// so most pairs never meet. Shows the cost following Σₜ nₜ² rather than n².
const Fixture& Sparse3000() {
  static const Fixture f = [] {
    Fixture fx;
    fx.chunk = {0, 200};
    fx.scene.camera = testing::SyntheticCamera(true);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int l = 0; l < 3000; ++l) {
      const int len = 20 + static_cast<int>(40 * u(rng));
      const int start = static_cast<int>((200 - len) * u(rng));
      const Eigen::Vector3d d = testing::Draw3([&] { return u(rng); });
      const Eigen::Vector3d p(-20 + 40 * d.x(), -5 + 10 * d.y(), 8 + 40 * d.z());
      for (int t = start; t < start + len; ++t) {
        Eigen::Vector3d x;
        fx.scene.camera.Project(Eigen::Vector3d(p.x(), p.y(), p.z() - 0.3 * (t - start)), &x);
        fx.scene.table.Add(l, t, x, Eigen::Matrix3d::Identity());
      }
    }
    fx.tracks = BackProjectTracks(fx.scene.table, fx.scene.camera, fx.chunk);
    return fx;
  }();
  return f;
}

void BM_MotionDistanceSparse3000x200(benchmark::State& state) {
  const Fixture& f = Sparse3000();
  size_t pairs = 0;
  for (auto _ : state) {
    const SparseDistances d = ComputeMotionDistances(f.scene.table, f.tracks, f.chunk, {});
    pairs = d.entries.size();
    benchmark::DoNotOptimize(d.entries.data());
  }
  state.counters["landmarks"] = f.scene.table.num_landmarks();
  state.counters["observations"] = static_cast<double>(f.scene.table.num_observations());
  state.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_MotionDistanceSparse3000x200)->Unit(benchmark::kMillisecond);

// HAC on that chunk's matrix (n = 3000 > max_dense_items: the hashed sparse engine).
void BM_HacSparse3000(benchmark::State& state) {
  const Fixture& f = Sparse3000();
  const SparseDistances d = ComputeMotionDistances(f.scene.table, f.tracks, f.chunk, {});
  HacOptions o;
  o.epsilon = 90.0;
  int clusters = 0;
  for (auto _ : state) {
    const auto labels = CompleteLinkageHac(d, o);
    clusters = *std::max_element(labels.begin(), labels.end()) + 1;
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["entries"] = static_cast<double>(d.entries.size());
  state.counters["clusters"] = clusters;
}
BENCHMARK(BM_HacSparse3000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cslam
