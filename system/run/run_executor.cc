#include "system/run/run_executor.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/timer.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

constexpr int kExitCouldNotStart = 127;

bool Interrupted(int exit_code) { return exit_code == 130 || exit_code == 143; }

std::string Duration(double s) {
  const long long t = std::llround(s);
  if (t < 60) return std::to_string(t) + " s";
  if (t < 3600) return std::to_string(t / 60) + " min " + std::to_string(t % 60) + " s";
  return std::to_string(t / 3600) + " h " + std::to_string(t / 60 % 60) + " min";
}

// fork + exec with stdout and stderr into `log`; returns the child's pid, or -1 with `why`.
pid_t Spawn(const RunTask& task, const std::string& log, std::string* why) {
  const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    *why = "cannot open " + log + ": " + std::strerror(errno);
    return -1;
  }
  std::vector<char*> argv;
  for (const std::string& a : task.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) {
    *why = std::string("fork failed: ") + std::strerror(errno);
    close(fd);
    return -1;
  }
  if (pid == 0) {
    setpgid(0, 0);  // its own group: a Ctrl-C reaches the suite, which forwards one SIGTERM
    dup2(fd, 1);
    dup2(fd, 2);
    execv(argv[0], argv.data());
    const std::string msg = "cannot start " + task.argv[0] + ": " + std::strerror(errno) + "\n";
    (void)!write(2, msg.data(), msg.size());
    _exit(kExitCouldNotStart);
  }
  close(fd);
  return pid;
}

}  // namespace

std::optional<CompletionMarker> ReadCompletionMarker(const std::string& dir) {
  std::ifstream in(fs::path(dir) / "exit_code");
  CompletionMarker marker;
  if (!(in >> marker.exit_code)) return std::nullopt;
  in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  std::getline(in, marker.reason);
  return marker;
}

std::vector<const RunTask*> TasksToRun(const std::vector<RunTask>& tasks, SuiteProgress* progress) {
  std::vector<const RunTask*> pending;
  for (const RunTask& t : tasks) {
    if (const auto marker = ReadCompletionMarker(t.dir)) {
      ++progress->done;
      ++progress->skipped;
      progress->failed += marker->exit_code != 0;
    } else {
      pending.push_back(&t);
    }
  }
  return pending;
}

void WriteCompletionMarker(const std::string& dir, int exit_code, const std::string& reason) {
  WriteFileAtomically((fs::path(dir) / "exit_code").string(), [&](std::ostream& o) {
    o << exit_code << "\n";
    if (!reason.empty()) o << reason << "\n";
  });
}

std::string ConsoleLogPath(const std::string& dir) { return (fs::path(dir) / "console.log").string(); }

std::string FileTail(const std::string& file, int lines) {
  std::ifstream in(file);
  if (!in) return "";
  std::deque<std::string> tail;
  std::string line;
  while (std::getline(in, line)) {
    tail.push_back(line);
    if (static_cast<int>(tail.size()) > lines) tail.pop_front();
  }
  std::string out;
  for (const std::string& l : tail) out += l + "\n";
  return out;
}

std::string SuiteProgress::Line() const {
  std::ostringstream s;
  s << "runs " << done << "/" << total << " done";
  if (skipped > 0) s << " (" << skipped << " already complete)";
  s << ", " << running << " running, " << failed << " failed, " << Duration(elapsed_s);
  if (eta_s) s << ", ETA " << Duration(*eta_s);
  return s.str();
}

void LocalExecutorOptions::Check() const {
  if (jobs < 1) throw ConfigError("--jobs: must be >= 1, got " + std::to_string(jobs));
}

void RunLocally(const std::vector<RunTask>& tasks, const LocalExecutorOptions& options,
                const std::atomic<bool>* stop,
                const std::function<void(const SuiteProgress&)>& on_progress) {
  options.Check();
  const Timer timer;
  SuiteProgress progress;
  progress.total = static_cast<int>(tasks.size());
  const std::vector<const RunTask*> pending = TasksToRun(tasks, &progress);
  std::map<pid_t, const RunTask*> running;
  double finished_run_s = 0.0;
  int finished_runs = 0;
  std::map<pid_t, double> started_at;
  bool terminated = false;
  auto report = [&] {
    progress.running = static_cast<int>(running.size());
    progress.elapsed_s = timer.ElapsedS();
    if (finished_runs > 0) {
      const double per_run = finished_run_s / finished_runs;
      const int left = progress.total - progress.done;
      progress.eta_s = per_run * left / options.jobs;
    }
    if (on_progress) on_progress(progress);
  };
  report();
  size_t next = 0;
  while (next < pending.size() || !running.empty()) {
    const bool stopping = stop && stop->load();
    if (stopping && !terminated) {
      for (const auto& [pid, task] : running) kill(pid, SIGTERM);
      terminated = true;
    }
    while (!stopping && next < pending.size() && static_cast<int>(running.size()) < options.jobs) {
      const RunTask& t = *pending[next++];
      std::error_code ec;
      fs::remove_all(t.dir, ec);  // a fresh folder: nothing of an earlier, unfinished attempt
      fs::create_directories(t.dir, ec);
      if (ec || !fs::is_directory(t.dir))
        throw OutputError(t.dir, "cannot create the run folder" + (ec ? ": " + ec.message() : ""));
      std::string why;
      const pid_t pid = Spawn(t, ConsoleLogPath(t.dir), &why);
      if (pid < 0) {
        WriteCompletionMarker(t.dir, kExitCouldNotStart, why);
        ++progress.done;
        ++progress.failed;
      } else {
        running[pid] = &t;
        started_at[pid] = timer.ElapsedS();
      }
      report();
    }
    if (running.empty()) {
      if (stopping) break;
      continue;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      report();
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    const RunTask& t = *it->second;
    running.erase(it);
    int code = 0;
    std::string reason;
    if (WIFEXITED(status)) {
      code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
      code = 128 + WTERMSIG(status);
      reason = std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
               strsignal(WTERMSIG(status)) + ")";
    }
    const bool interrupted = Interrupted(code);
    if (!interrupted) {
      WriteCompletionMarker(t.dir, code, reason);
      ++progress.done;
      progress.failed += code != 0;
      finished_run_s += timer.ElapsedS() - started_at[pid];
      ++finished_runs;
    }
    started_at.erase(pid);
    report();
  }
  report();
}

}  // namespace cslam
