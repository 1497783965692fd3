#pragma once
// Shared plumbing of the commands that run the system (run, demo, bench): the common flags,
// output folder checks, the log file, Ctrl-C handling, a progress bar, and the end of a run.
#include <CLI/CLI.hpp>

#include <atomic>
#include <string>

#include "system/pipeline/pipeline.h"
#include "system/pipeline/pipeline_options.h"
#include "system/pipeline/run_input.h"

namespace cslam::apps {

/// Flags shared by `run` and `demo`; each overrides the same field of PipelineOptions.
struct RunFlags {
  std::string config;       ///< YAML file ("" = built-in defaults)
  // Words of kPresetNames, kMethodNames, kAblationNames, kRunModeNames ("" = not given).
  std::string preset;       ///< "" = from the input kind
  std::string method;
  std::string ablation;
  std::string mode;
  bool realtime = false;
  bool sequential = false;
  int snapshots_every = -1;
  int overlays_every = -1;
  int max_frames = 0;
  std::string cameras = "grey";
  bool progress = true;

  void Register(CLI::App* sub);
  InputOptions InputOptionsFor() const;
  /// Defaults for the input's kind, then --config, then the flags. Throws ConfigError.
  PipelineOptions Resolve(const RunInput& input) const;
};

/// Creates `out` and checks it is writable; throws OutputError naming it otherwise.
void PrepareOutputFolder(const std::string& out);
/// Adds a file sink to every logger (existing and future).
void AttachLogFile(const std::string& path);

/// Installs SIGINT/SIGTERM handlers for its lifetime; the first signal asks the run to stop
/// (outputs are still written), a second one ends the process at once.
class StopFlag {
 public:
  StopFlag();
  ~StopFlag();
  const std::atomic<bool>* flag() const;
  /// 0, SIGINT or SIGTERM.
  int signal() const;
};

/// A one-line progress bar on stderr (only when stderr is a terminal).
class ProgressBar {
 public:
  ProgressBar(std::string what, bool enabled);
  void Update(int done, int total);
  void Finish();

 private:
  std::string what_;
  bool enabled_;
  int last_percent_ = -1;
};

/// Builds the run's trajectories once, evaluates them (metrics, where there is ground truth)
/// and writes them with every other output, prints a summary and
/// returns the exit code: the pipeline's error is rethrown after the outputs are written;
/// 130/143 after SIGINT/SIGTERM.
int FinishRun(const RunInput& input, const PipelineResult& result, const PipelineOptions& options,
              const std::string& out, const StopFlag& stop);

}  // namespace cslam::apps
