#pragma once
// Runs the `cslam run` children of a suite as one Slurm array job (`sbatch --array`), each
// task one run, on the shared filesystem a cluster has. Every task runs a generated script
// DIR/slurm/task_<k>.sh that does what the local executor does: a fresh run folder, the
// child's output into console.log, then DIR/runs/<id>/exit_code written last (not after
// SIGINT/SIGTERM). Runs already complete are left out of the array (resume). Nothing about
// the machine is assumed: sbatch, squeue and sacct are found on PATH, and the resources are
// those given (partition, time, memory, CPUs per task, account), else the cluster's defaults.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "system/run/run_executor.h"
#include "system/run/suite_manifest.h"

namespace cslam {

/// How the array job is submitted and watched.
struct SlurmExecutorOptions {
  SuiteSlurmOptions resources;
  double poll_s = 5.0;  ///< seconds between squeue polls, > 0
  bool wait = true;     ///< false: submit and return (then `cslam bench collect DIR`)
  /// Throws ConfigError naming the option.
  void Check() const;
};

/// The script of one task: a POSIX shell script that runs `task` as described above.
std::string SlurmTaskScript(const RunTask& task);

/// The array job's batch script for `count` tasks whose scripts are in `slurm_dir`.
std::string SlurmArrayScript(const std::string& slurm_dir, int count,
                             const SuiteSlurmOptions& resources);

/// Writes the scripts into `suite_out`/slurm, submits the tasks not yet complete as one
/// array job and, with options.wait, polls squeue until it has ended; then every task left
/// without a marker gets one from sacct's state (TIMEOUT, OUT_OF_MEMORY, ...) when sacct
/// knows it. Returns the job id ("" when every task was already complete). Throws
/// ConfigError when sbatch is not on PATH or refuses the job (its message included).
std::string RunOnSlurm(const std::vector<RunTask>& tasks, const SlurmExecutorOptions& options,
                       const std::string& suite_out, const std::atomic<bool>* stop,
                       const std::function<void(const SuiteProgress&)>& on_progress = {});

}  // namespace cslam
