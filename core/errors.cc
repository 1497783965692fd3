#include "core/errors.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace cslam {

namespace {
std::string Located(const std::string& file, int line, const std::string& what) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  return s + ": " + what;
}
}  // namespace

ConfigError::ConfigError(std::string key, const std::string& rule)
    : Error(key + ": " + rule), key_(std::move(key)), rule_(rule) {}

InputError::InputError(const std::string& file, int line, const std::string& what)
    : Error(Located(file, line, what)) {}

OutputError::OutputError(const std::string& file, const std::string& what)
    : Error(Located(file, 0, what)) {}

void CheckFailed(const char* expr, const char* file, int line, const std::string& msg) {
  std::fprintf(stderr, "internal error: check '%s' failed at %s:%d: %s\n", expr, file, line,
               msg.c_str());
  std::abort();
}

}  // namespace cslam
