#pragma once
// Error taxonomy (docs/usage.md lists the exit codes):
//  - broken invariants abort through CSLAM_CHECK with a message;
//  - bad configuration throws ConfigError (the app exits 2);
//  - unreadable or malformed input throws InputError naming the file and line (exit 1);
//  - an output that cannot be written throws OutputError (exit 3);
//  - a run whose every backend window was discarded writes its outputs and exits 5;
//  - expected algorithmic outcomes are reported in result structs, never thrown.
#include <stdexcept>
#include <string>

namespace cslam {

/// Process exit codes of the `cslam` program.
enum ExitCode : int {
  kExitOk = 0,
  kExitInputError = 1,
  kExitConfigError = 2,
  kExitOutputError = 3,
  kExitInternalError = 4,
  /// The run finished but every backend window was discarded: the outputs hold no estimate.
  kExitNoEstimate = 5,
  kExitSigint = 130,
  kExitSigterm = 143,
};

/// Base class of every error the libraries throw on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  virtual int exit_code() const { return kExitInternalError; }
};

/// A configuration value or key is wrong; the message names the key and the rule.
class ConfigError : public Error {
 public:
  using Error::Error;
  /// "key: rule". Keeping `key` (a dotted path relative to the section that threw) apart lets
  /// each enclosing section prefix its own name, and the loader add the file and line.
  ConfigError(std::string key, const std::string& rule);
  int exit_code() const override { return kExitConfigError; }
  /// The key path; empty when the error was not raised for one key.
  const std::string& key() const { return key_; }
  /// What is wrong with the value at key() ("must be >= 1, got 0").
  const std::string& rule() const { return rule_; }

 private:
  std::string key_;
  std::string rule_;
};

/// An input file or folder is missing, unreadable or malformed.
class InputError : public Error {
 public:
  /// `file` and (when > 0) `line` are prefixed to the message: "file:line: what".
  InputError(const std::string& file, int line, const std::string& what);
  InputError(const std::string& file, const std::string& what) : InputError(file, 0, what) {}
  int exit_code() const override { return kExitInputError; }
};

/// An output could not be written.
class OutputError : public Error {
 public:
  OutputError(const std::string& file, const std::string& what);
  int exit_code() const override { return kExitOutputError; }
};

[[noreturn]] void CheckFailed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace cslam

/// Aborts with a message when an internal invariant does not hold (a bug, not bad input).
#define CSLAM_CHECK(cond, msg)                                           \
  do {                                                                   \
    if (!(cond)) ::cslam::CheckFailed(#cond, __FILE__, __LINE__, (msg)); \
  } while (0)
