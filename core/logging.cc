#include "core/logging.h"

#include <mutex>

namespace cslam {

std::shared_ptr<spdlog::logger> GetLogger(const std::string& name) {
  // spdlog's registry is the one process-wide place loggers live; creation is serialised
  // so two threads asking for a new name get the same logger.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto logger = spdlog::get(name)) return logger;
  auto def = spdlog::default_logger();
  auto logger = std::make_shared<spdlog::logger>(name, def->sinks().begin(), def->sinks().end());
  logger->set_level(def->level());
  spdlog::register_logger(logger);
  return logger;
}

}  // namespace cslam
