#pragma once
// One named spdlog logger per layer ("core", "frontend", "backend", "system", "app").
// Libraries only log; sinks and levels are set by the app.
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

namespace cslam {

/// The logger named `name`, created on first use with the default sinks.
std::shared_ptr<spdlog::logger> GetLogger(const std::string& name);

}  // namespace cslam
