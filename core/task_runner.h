#pragma once
// An interface for running independent tasks side by side.
//
// Why an interface in core: the decoupled bundle adjustment's solves (each moving cluster, and
// the static world) share no unknowns, so they can run concurrently, but threads belong to
// system/ (docs/architecture.md). The backend takes a TaskRunner in its options; system/
// supplies one backed by threads (system/runtime/worker_pool.h), and without one the tasks run one
// after another on the caller's thread.
#include <functional>

namespace cslam {

/// Runs task(0) … task(n − 1), possibly concurrently, and returns when every one has returned.
/// The tasks must touch disjoint data. If tasks throw, the first exception is rethrown here
/// after all have finished.
class TaskRunner {
 public:
  virtual ~TaskRunner() = default;
  virtual void Run(int n, const std::function<void(int)>& task) const = 0;
  /// CPU time, ms, that threads other than the callers' have spent on tasks so far (0 when
  /// every task runs on the caller's thread): a caller's own thread CPU clock misses it.
  virtual double HelperCpuMs() const { return 0.0; }
};

/// Calls `task` for every index in order on the calling thread, through `runner` when given.
void RunTasks(const TaskRunner* runner, int n, const std::function<void(int)>& task);

}  // namespace cslam
