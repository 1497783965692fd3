#pragma once
// The threads behind the backend's TaskRunner (core/task_runner.h).
#include <atomic>
#include <functional>

#include "core/task_runner.h"

namespace cslam {

/// Runs a batch of tasks on `threads` threads: the caller's and threads − 1 started for the
/// batch and joined before Run returns. Why not keep them alive: a batch is one bundle
/// adjustment's solves, tens of milliseconds of work, against tens of microseconds to start a
/// thread; threads that only live inside Run leave nothing running between windows and
/// nothing to shut down.
class WorkerPool final : public TaskRunner {
 public:
  /// `threads` ≥ 1 (1: every task on the caller's thread). `on_helper_start`, if set, runs
  /// first on every started thread (system/runtime/core_reservation.h moves it off a reserved CPU).
  explicit WorkerPool(int threads, std::function<void()> on_helper_start = {});
  int threads() const { return threads_; }
  void Run(int n, const std::function<void(int)>& task) const override;
  double HelperCpuMs() const override { return helper_cpu_us_.load() * 1e-3; }

 private:
  int threads_;
  std::function<void()> on_helper_start_;
  mutable std::atomic<long long> helper_cpu_us_{0};  // summed over the started threads' lives
};

}  // namespace cslam
