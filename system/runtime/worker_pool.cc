#include "system/runtime/worker_pool.h"

#include <algorithm>
#include <ctime>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace cslam {

WorkerPool::WorkerPool(int threads, std::function<void()> on_helper_start)
    : threads_(threads), on_helper_start_(std::move(on_helper_start)) {
  CSLAM_CHECK(threads >= 1, "WorkerPool needs at least one thread");
}

void WorkerPool::Run(int n, const std::function<void(int)>& task) const {
  std::atomic<int> next{0};
  std::mutex mutex;
  std::exception_ptr first_error;
  // Each thread takes the next undone index until none is left, so a long task (the static
  // solve) does not hold back the short ones queued behind it.
  auto work = [&] {
    for (int i; (i = next.fetch_add(1)) < n;) {
      try {
        task(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
      }
    }
  };
  {
    std::vector<std::jthread> helpers;
    for (int t = 1; t < std::min(threads_, n); ++t)
      helpers.emplace_back([&] {
        if (on_helper_start_) on_helper_start_();
        work();
        // The thread was started for this batch, so its CPU clock is its share of the work.
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        helper_cpu_us_ += ts.tv_sec * 1000000LL + ts.tv_nsec / 1000;
      });
    work();
  }  // joined here
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace cslam
