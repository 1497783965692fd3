#pragma once
// Wall-clock timing for per-stage statistics.
#include <chrono>

namespace cslam {

/// Starts on construction; ElapsedMs() reads the wall clock since then.
class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  double ElapsedMs() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }
  double ElapsedS() const { return ElapsedMs() * 1e-3; }
  void Reset() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace cslam
