#pragma once
// Runs the `cslam run` child processes of a suite on this machine, N at a time. Each task has
// its own folder: the child's stdout and stderr go to DIR/console.log (captured by the
// executor, so a run rejected at start still leaves its message), and when the child has
// ended the executor writes DIR/exit_code last — the completion marker. A task whose folder
// already has the marker is skipped (resume). A child stopped by SIGINT/SIGTERM (exit 130/143
// or killed by those signals) gets no marker, so it is redone next time.
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cslam {

/// One child process.
struct RunTask {
  std::string id;
  std::string dir;                ///< its folder (created afresh unless complete)
  std::vector<std::string> argv;  ///< argv[0] is the program path
};

/// A complete task's DIR/exit_code: the child's exit code (128 + signal when it was killed) and
/// the executor's reason line, if it wrote one (a signal, a Slurm state, why it could not start).
struct CompletionMarker {
  int exit_code = 0;
  std::string reason;
};

/// Reads DIR/exit_code, or empty when the marker is missing or unreadable (the task is not
/// complete).
std::optional<CompletionMarker> ReadCompletionMarker(const std::string& dir);

/// Writes DIR/exit_code atomically: "<code>\n" then an optional reason line.
void WriteCompletionMarker(const std::string& dir, int exit_code, const std::string& reason = "");

/// The console.log file of a task folder.
std::string ConsoleLogPath(const std::string& dir);

/// The last `lines` lines of a text file ("" when it cannot be read).
std::string FileTail(const std::string& file, int lines = 12);

/// Where the suite stands, for the progress line.
struct SuiteProgress {
  int total = 0, done = 0, running = 0, failed = 0, skipped = 0;
  double elapsed_s = 0.0;
  std::optional<double> eta_s;  ///< unknown until a run has finished
  /// "runs 3/10 done (1 skipped), 2 running, 1 failed, 41 s, ETA 1 min 20 s"
  std::string Line() const;
};

/// The tasks whose completion marker is missing, in order; the complete ones count into
/// `progress` as done and skipped (and failed when their exit code is not 0).
std::vector<const RunTask*> TasksToRun(const std::vector<RunTask>& tasks, SuiteProgress* progress);

/// How the local executor runs its tasks.
struct LocalExecutorOptions {
  int jobs = 1;  ///< child processes at once, >= 1
  /// Throws ConfigError naming --jobs.
  void Check() const;
};

/// Runs every task not yet complete, at most options.jobs at a time, and returns when all
/// have ended or, after *stop became true, when the running ones have ended (they are sent
/// SIGTERM once; the tasks not started stay incomplete). `on_progress` is called from this
/// thread whenever a task starts or ends. Throws OutputError when a task folder cannot be
/// created; a child that cannot be started ends with exit code 127 and its reason.
void RunLocally(const std::vector<RunTask>& tasks, const LocalExecutorOptions& options,
                const std::atomic<bool>* stop,
                const std::function<void(const SuiteProgress&)>& on_progress = {});

}  // namespace cslam
