#include "system/runtime/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <stdexcept>
#include <thread>
#include <vector>

#include "backend/bundle_adjustment.h"
#include "backend/motion_estimation.h"
#include "tests/backend/synthetic_bodies.h"

namespace cslam {
namespace {

TEST(WorkerPool, RunsEveryTaskExactlyOnceForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8})
    for (int n : {0, 1, 2, 7, 100}) {
      std::vector<std::atomic<int>> calls(n);
      WorkerPool(threads).Run(n, [&](int i) { ++calls[i]; });
      for (int i = 0; i < n; ++i) EXPECT_EQ(calls[i].load(), 1) << threads << " threads, task " << i;
    }
}

/// Spins on the CPU until this thread has used `ms` of it.
void BurnThreadCpu(double ms) {
  const auto cpu_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  };
  const double start = cpu_ms();
  volatile double sink = 0.0;
  while (cpu_ms() - start < ms) sink = sink + 1.0;
}

TEST(WorkerPool, CountsTheCpuItsOwnThreadsSpendButNotTheCallers) {
  // The run log's backend CPU is the backend thread's clock; what the started threads spend
  // must come from the pool. Two 30 ms tasks on two threads, each waiting (sleeping, up to
  // 10 s) until both have started, so the started thread runs exactly one.
  const WorkerPool two(2);
  EXPECT_EQ(two.HelperCpuMs(), 0.0);
  std::atomic<int> started{0}, on_helper{0};
  const auto caller = std::this_thread::get_id();
  two.Run(2, [&](int) {
    if (std::this_thread::get_id() != caller) ++on_helper;
    ++started;
    for (int i = 0; i < 10000 && started.load() < 2; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    BurnThreadCpu(30.0);
  });
  ASSERT_EQ(on_helper.load(), 1);
  EXPECT_GE(two.HelperCpuMs(), 30.0);
  EXPECT_LT(two.HelperCpuMs(), 50.0);
  // One thread: everything on the caller's clock, nothing to add.
  const WorkerPool one(1);
  one.Run(2, [](int) { BurnThreadCpu(5.0); });
  EXPECT_EQ(one.HelperCpuMs(), 0.0);
}

TEST(WorkerPool, TwoThreadsRunTwoTasksAtTheSameTime) {
  // Each task waits (up to 10 s) until the other has started: only a concurrent run lets both
  // see it; one after another, the first would time out.
  std::atomic<int> started{0};
  std::atomic<int> saw_other{0};
  WorkerPool(2).Run(2, [&](int) {
    ++started;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started.load() < 2 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::yield();
    if (started.load() == 2) ++saw_other;
  });
  EXPECT_EQ(saw_other.load(), 2);
}

TEST(WorkerPool, AThrowingTaskIsRethrownAfterTheOthersFinished) {
  for (int threads : {1, 2}) {
    std::atomic<int> finished{0};
    EXPECT_THROW(WorkerPool(threads).Run(6,
                                         [&](int i) {
                                           if (i == 1) throw std::runtime_error("task 1");
                                           ++finished;
                                         }),
                 std::runtime_error);
    EXPECT_EQ(finished.load(), 5) << threads << " threads";
  }
}

/// A WorkerPool that records how many tasks it was handed.
class CountingPool final : public TaskRunner {
 public:
  void Run(int n, const std::function<void(int)>& task) const override {
    tasks += n;
    pool_.Run(n, task);
  }
  mutable std::atomic<int> tasks{0};

 private:
  WorkerPool pool_{2};
};

TEST(WorkerPool, DecoupledBundleAdjustmentGivesTheSameEstimateOnTwoThreads) {
  testing::BodySceneSpec spec;
  spec.num_frames = 20;
  spec.num_moving = 3;
  spec.points_per_body = 40;
  spec.num_static = 200;
  const testing::BodyScene scene = testing::MakeBodyScene(spec);
  MotionEstimationOptions init;
  init.run_bundle_adjustment = false;
  const MotionEstimate start =
      EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, init);
  ASSERT_EQ(start.clusters.size(), 3u);

  BundleAdjustmentOptions one;
  MotionEstimate alone = start;
  const BundleAdjustmentSummary s1 = AdjustBundle(scene.table, scene.camera, one, &alone);
  BundleAdjustmentOptions two;
  const auto pool = std::make_shared<CountingPool>();
  two.runner = pool;
  MotionEstimate side_by_side = start;
  const BundleAdjustmentSummary s2 = AdjustBundle(scene.table, scene.camera, two, &side_by_side);

  // Bit for bit: the solves share no unknowns and each runs the same arithmetic.
  EXPECT_LT(s1.final_chi2, s1.initial_chi2);
  EXPECT_EQ(s1.final_chi2, s2.final_chi2);
  EXPECT_EQ(s1.iterations, s2.iterations);
  EXPECT_EQ(s1.num_solves, s2.num_solves);
  EXPECT_EQ(s1.num_solves, 4);
  EXPECT_EQ(pool->tasks.load(), 4);  // the static world and the three bodies
  for (size_t f = 0; f < alone.world_from_cam.size(); ++f)
    EXPECT_EQ(alone.world_from_cam[f].matrix(), side_by_side.world_from_cam[f].matrix()) << f;
  for (size_t l = 0; l < alone.landmark_in_cluster.size(); ++l)
    if (alone.landmark_in_cluster[l].allFinite())
      EXPECT_EQ(alone.landmark_in_cluster[l], side_by_side.landmark_in_cluster[l]) << l;
  ASSERT_EQ(alone.clusters.size(), side_by_side.clusters.size());
  for (size_t c = 0; c < alone.clusters.size(); ++c)
    for (size_t k = 0; k < alone.clusters[c].cam_from_cluster.size(); ++k)
      EXPECT_EQ(alone.clusters[c].cam_from_cluster[k].matrix(),
                side_by_side.clusters[c].cam_from_cluster[k].matrix());
}

}  // namespace
}  // namespace cslam
