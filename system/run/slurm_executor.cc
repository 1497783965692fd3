#include "system/run/slurm_executor.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/timer.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The program's full path on PATH, or "".
std::string FindOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir) / program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

// Runs a shell command; its stdout and stderr together, and its exit status.
std::string Capture(const std::string& command, int* status) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) {
    *status = -1;
    return "";
  }
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) out.append(buf, n);
  const int rc = pclose(pipe);
  *status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return out;
}

std::string Trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

}  // namespace

void SlurmExecutorOptions::Check() const {
  resources.Check();
  if (!(poll_s > 0)) throw ConfigError("--slurm-poll: must be > 0 seconds");
}

std::string SlurmTaskScript(const RunTask& task) {
  std::ostringstream s;
  const std::string dir = Quote(task.dir);
  s << "#!/bin/sh\n# cslam bench: run " << task.id << "\n"
    << "rm -rf " << dir << " && mkdir -p " << dir << " || exit 3\n";
  for (size_t i = 0; i < task.argv.size(); ++i) s << (i ? " " : "") << Quote(task.argv[i]);
  s << " > " << Quote(ConsoleLogPath(task.dir)) << " 2>&1\nrc=$?\n"
    << "case $rc in 130|143) exit $rc ;; esac  # interrupted: no marker, redone on resume\n"
    << "printf '%s\\n' \"$rc\" > " << Quote(task.dir + "/.exit_code.tmp") << " && mv "
    << Quote(task.dir + "/.exit_code.tmp") << " " << Quote(task.dir + "/exit_code") << "\n"
    << "exit $rc\n";
  return s.str();
}

std::string SlurmArrayScript(const std::string& slurm_dir, int count,
                             const SuiteSlurmOptions& r) {
  std::ostringstream s;
  s << "#!/bin/sh\n#SBATCH --job-name=cslam-bench\n#SBATCH --array=0-" << count - 1 << "\n"
    << "#SBATCH --output=" << slurm_dir << "/task_%a.slurm.log\n";
  if (!r.partition.empty()) s << "#SBATCH --partition=" << r.partition << "\n";
  if (!r.time.empty()) s << "#SBATCH --time=" << r.time << "\n";
  if (!r.mem.empty()) s << "#SBATCH --mem=" << r.mem << "\n";
  if (r.cpus_per_task > 0) s << "#SBATCH --cpus-per-task=" << r.cpus_per_task << "\n";
  if (!r.account.empty()) s << "#SBATCH --account=" << r.account << "\n";
  s << "exec sh " << Quote(slurm_dir) << "/task_${SLURM_ARRAY_TASK_ID}.sh\n";
  return s.str();
}

std::string RunOnSlurm(const std::vector<RunTask>& tasks, const SlurmExecutorOptions& options,
                       const std::string& suite_out, const std::atomic<bool>* stop,
                       const std::function<void(const SuiteProgress&)>& on_progress) {
  options.Check();
  const std::string sbatch = FindOnPath("sbatch");
  if (sbatch.empty())
    throw ConfigError(
        "--executor slurm: sbatch not found on PATH; install the Slurm client (Debian: "
        "slurm-client, or scripts/slurm-local.sh for a one-machine Slurm) or add its folder to "
        "PATH; --executor local runs the suite on this machine");
  const Timer timer;
  SuiteProgress progress;
  progress.total = static_cast<int>(tasks.size());
  const std::vector<const RunTask*> pending = TasksToRun(tasks, &progress);
  // The submitted tasks that have ended so far, by their markers.
  auto count_ended = [&] {
    int done = 0, failed = 0;
    for (const RunTask* t : pending)
      if (const auto marker = ReadCompletionMarker(t->dir)) {
        ++done;
        failed += marker->exit_code != 0;
      }
    progress.done = progress.skipped + done;
    progress.failed = failed;
  };
  auto report = [&] {
    progress.elapsed_s = timer.ElapsedS();
    if (on_progress) on_progress(progress);
  };
  report();
  if (pending.empty()) return "";

  const std::string slurm_dir = (fs::absolute(suite_out) / "slurm").lexically_normal().string();
  std::error_code ec;
  fs::remove_all(slurm_dir, ec);
  for (size_t k = 0; k < pending.size(); ++k)
    WriteFileAtomically(slurm_dir + "/task_" + std::to_string(k) + ".sh",
                        [&](std::ostream& o) { o << SlurmTaskScript(*pending[k]); });
  const std::string array = slurm_dir + "/array.sh";
  WriteFileAtomically(array, [&](std::ostream& o) {
    o << SlurmArrayScript(slurm_dir, static_cast<int>(pending.size()), options.resources);
  });
  int status = 0;
  const std::string out = Trim(Capture(Quote(sbatch) + " --parsable " + Quote(array), &status));
  if (status != 0)
    throw ConfigError("--executor slurm: sbatch refused the job (exit " + std::to_string(status) +
                      "): " + out + " (check the partition, time, mem and account of the "
                      "manifest's slurm: section or the --slurm-* flags)");
  const std::string job = out.substr(0, out.find(';'));  // "jobid[;cluster]"
  WriteFileAtomically(slurm_dir + "/job_id", [&](std::ostream& o) { o << job << "\n"; });
  if (!options.wait) return job;

  // Wait until squeue no longer lists the job; count markers meanwhile.
  const std::string squeue = FindOnPath("squeue");
  bool cancelled = false;
  while (true) {
    if (stop && stop->load() && !cancelled) {
      if (const std::string scancel = FindOnPath("scancel"); !scancel.empty()) {
        int st = 0;
        Capture(Quote(scancel) + " " + Quote(job), &st);
      }
      cancelled = true;
    }
    count_ended();
    int st = 0;
    const std::string listed =
        squeue.empty() ? "" : Trim(Capture(Quote(squeue) + " -h -o %i -j " + Quote(job), &st));
    progress.running = listed.empty() ? 0 : static_cast<int>(std::count(listed.begin(), listed.end(), '\n') + 1);
    report();
    if (squeue.empty() || st != 0 || listed.empty()) break;
    std::this_thread::sleep_for(std::chrono::duration<double>(options.poll_s));
  }
  // Tasks killed by Slurm (time, memory, node failure) never wrote their marker: sacct says why.
  if (const std::string sacct = FindOnPath("sacct"); !sacct.empty()) {
    int st = 0;
    std::istringstream lines(
        Capture(Quote(sacct) + " -n -P -X -o JobID,State,ExitCode -j " + Quote(job), &st));
    std::string line;
    while (st == 0 && std::getline(lines, line)) {
      std::istringstream f(line);
      std::string id, state, exit;
      std::getline(f, id, '|');
      std::getline(f, state, '|');
      std::getline(f, exit, '|');
      const size_t us = id.find('_');
      if (us == std::string::npos) continue;
      int k = -1;
      try {
        k = std::stoi(id.substr(us + 1));
      } catch (...) {
        continue;
      }
      if (k < 0 || k >= static_cast<int>(pending.size())) continue;
      const RunTask& t = *pending[k];
      if (ReadCompletionMarker(t.dir)) continue;
      state = state.substr(0, state.find(' '));  // "CANCELLED by 0"
      if (state == "TIMEOUT" || state == "OUT_OF_MEMORY" || state == "NODE_FAIL" ||
          state == "FAILED" || state == "BOOT_FAIL" || state == "DEADLINE" ||
          (state == "CANCELLED" && !cancelled)) {
        fs::create_directories(t.dir, ec);
        WriteCompletionMarker(t.dir, 128 + 9, "Slurm task " + id + " ended " + state);
      }
    }
  }
  count_ended();
  progress.running = 0;
  report();
  return job;
}

}  // namespace cslam
