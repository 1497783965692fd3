#pragma once
// Shared plumbing of the commands that run the system (run, demo, bench): the common flags,
// output folder checks, the log file, Ctrl-C handling, a progress bar, and the end of a run.
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
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
  int pictures = -1;  ///< final-state pictures (output.final_pictures); -1 = not given
  int max_frames = 0;
  std::string cameras;       ///< "" = the configuration's input.color (default grey)
  bool progress = true;
  bool overwrite = false;    ///< replace an earlier run's outputs in --out
  bool verbose = false;      ///< the info log (per-window lines) on the console too

  void Register(CLI::App* sub);
  InputOptions InputOptionsFor() const;
  /// Defaults for the input's kind, then --config, then the flags. Throws ConfigError.
  PipelineOptions Resolve(const RunInput& input) const;
};

/// Prepares `out` for the run of `command` over `input` (system/run/output_folder.h: an
/// earlier run's outputs are refused unless `overwrite`) and records the input there.
void PrepareRunFolder(const std::string& out, const std::string& command, const RunInput& input,
                      const RunFlags& flags);
/// The console keeps only warnings and errors unless `verbose` (or a --log-level below info
/// was asked for); the info log goes to run.log.
void QuietConsole(bool verbose);
/// Adds a file sink to every logger (existing and future).
void AttachLogFile(const std::string& path);
/// Writes `text` to run.log only (the effective configuration: it is in config.yaml, and 250
/// lines on the console hide what matters there).
void LogToRunLogOnly(const std::string& text);
/// What the console shows first: the input line and where the configuration came from.
void PrintRunHeader(const RunInput& input, const PipelineOptions& options, const std::string& out);

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

/// A one-line progress bar on stderr (only when stderr is a terminal), with the rate and,
/// when given (>= 0), the objects found so far.
class ProgressBar {
 public:
  ProgressBar(std::string what, bool enabled);
  void Update(int done, int total, int objects = -1);
  void Finish();

 private:
  std::string what_;
  bool enabled_;
  int last_percent_ = -1;
  int last_objects_ = -1;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// Builds the run's trajectories once, evaluates them (metrics, where there is ground truth)
/// and writes them with every other output, prints a summary, then draws the pictures (a
/// picture that cannot be drawn or written is reported and loses nothing else) and completes
/// the output manifest. Returns the exit code: the pipeline's error is rethrown after the
/// outputs are written; 130/143 after SIGINT/SIGTERM; 5 when no window was usable; 3 when a
/// picture was not written.
int FinishRun(const RunInput& input, const PipelineResult& result, const PipelineOptions& options,
              const std::string& out, const StopFlag& stop);

}  // namespace cslam::apps
