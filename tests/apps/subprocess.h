#pragma once
// Runs the built `cslam` program as a child process (stdout and stderr to files), so the CLI
// tests see exactly what a user sees: the exit code, the message and the files left behind.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace cslam::testing {

namespace fs = std::filesystem;

struct ProcessResult {
  int exit_code = -1;     ///< WEXITSTATUS, or 128 + signal when killed by a signal
  bool signalled = false; ///< the process was killed by a signal (a crash, unless we sent it)
  std::string out, err;
};

inline std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `args` (args[0] is the program path) with stdout/stderr captured in `log_dir`.
/// `while_running(pid, stderr_path)` runs in the parent before the wait (e.g. to send a
/// signal). Kills the child after `timeout`.
inline ProcessResult RunProcess(const std::vector<std::string>& args, const fs::path& log_dir,
                                const std::function<void(pid_t, const fs::path&)>& while_running = {},
                                std::chrono::seconds timeout = std::chrono::seconds(300)) {
  fs::create_directories(log_dir);
  const fs::path out_path = log_dir / "stdout.txt", err_path = log_dir / "stderr.txt";
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) _exit(127);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  if (while_running) while_running(pid, err_path);
  ProcessResult r;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (WIFEXITED(status)) {
    r.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.signalled = true;
    r.exit_code = 128 + WTERMSIG(status);
  }
  r.out = Slurp(out_path);
  r.err = Slurp(err_path);
  return r;
}

/// Waits until `file` contains `needle` (true) or `timeout` passes (false).
inline bool WaitForText(const fs::path& file, const std::string& needle, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (Slurp(file).find(needle) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

/// Every regular file under `dir` whose name says it is a temporary of an atomic write.
inline std::vector<std::string> TemporaryFilesUnder(const fs::path& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return found;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp") != std::string::npos) found.push_back(e.path().string());
  return found;
}

}  // namespace cslam::testing
