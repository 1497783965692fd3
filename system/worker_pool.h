#pragma once
// The threads behind the backend's TaskRunner (core/task_runner.h).
#include <atomic>

#include "core/task_runner.h"

namespace cslam {

/// Runs a batch of tasks on `threads` threads: the caller's and threads − 1 started for the
/// batch and joined before Run returns. Why not keep them alive: a batch is one bundle
/// adjustment's solves, tens of milliseconds of work, against tens of microseconds to start a
/// thread; threads that only live inside Run leave nothing running between windows and
/// nothing to shut down.
class WorkerPool final : public TaskRunner {
 public:
  /// `threads` ≥ 1 (1: every task on the caller's thread).
  explicit WorkerPool(int threads);
  int threads() const { return threads_; }
  void Run(int n, const std::function<void(int)>& task) const override;
  double HelperCpuMs() const override { return helper_cpu_us_.load() * 1e-3; }

 private:
  int threads_;
  mutable std::atomic<long long> helper_cpu_us_{0};  // summed over the started threads' lives
};

}  // namespace cslam
