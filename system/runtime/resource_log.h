#pragma once
// Resident memory and frame rate over a run, sampled every few frames, for the long-run
// checks of docs/reliability.md ("Load"): resources.csv (its chart, render/resources.png, is
// drawn by system/run/resource_chart.h: the threads' library draws no pictures).
#include <string>
#include <vector>

#include "core/timer.h"

namespace cslam {

/// The process's state after a frame was tracked.
struct ResourceSample {
  int frame = 0;           ///< frames tracked so far
  double elapsed_s = 0.0;  ///< since the run started
  double rss_mb = 0.0;     ///< resident set size, MiB (0 where /proc is not available)
};

/// Resident set size of this process in MiB, from /proc/self/statm (0 if unreadable).
double ResidentMegabytes();

/// Peak resident set size of this process so far in MiB, from getrusage(RUSAGE_SELF)
/// ru_maxrss (kilobytes on Linux); 0 if unavailable.
double PeakResidentMegabytes();

/// Samples every `every` frames (and whenever Finish is called) from the run's start.
class ResourceSampler {
 public:
  explicit ResourceSampler(int every = 10) : every_(every) {}
  /// Called after each tracked frame with the number of frames tracked so far.
  void AfterFrame(int frames_done);
  /// A last sample at the end of the run (unless one was just taken).
  void Finish(int frames_done);
  const std::vector<ResourceSample>& samples() const { return samples_; }
  std::vector<ResourceSample>& samples() { return samples_; }

 private:
  int every_;
  Timer timer_;
  std::vector<ResourceSample> samples_;
};

/// Frames per second between consecutive samples (one value per sample after the first).
std::vector<double> FramesPerSecond(const std::vector<ResourceSample>& samples);

/// Writes out_dir/resources.csv (frame, elapsed_s, rss_mb, fps). Fewer than two samples:
/// nothing is written.
void WriteResourceLog(const std::vector<ResourceSample>& samples, const std::string& out_dir);

/// Reads resources.csv back (for `cslam render`). Throws InputError naming the file and line.
std::vector<ResourceSample> ReadResourceLog(const std::string& path);

}  // namespace cslam
