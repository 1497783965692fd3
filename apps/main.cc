// The `cslam` program: thin glue over system/. Errors thrown by the libraries become exit
// codes here (docs/usage.md): input 1, configuration 2, output 3, internal 4.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <glog/logging.h>
#include <cstdio>
#include <exception>
#include <vector>

#include "apps/command.h"
#include "core/errors.h"
#include "system/run/version.h"

int main(int argc, char** argv) {
  CLI::App app{
      "clusterslam: stereo SLAM that also discovers and tracks every independently moving rigid "
      "body (ClusterSLAM backend)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", cslam::VersionString());
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));

  std::vector<cslam::apps::Command> commands = {
      cslam::apps::AddDemoCommand(app),
      cslam::apps::AddRunCommand(app),
      cslam::apps::AddSynthCommand(app),
      cslam::apps::AddEvalCommand(app),
      cslam::apps::AddBenchCommand(app),
      cslam::apps::AddRenderCommand(app),
      cslam::apps::AddCalibCommand(app),
      cslam::apps::AddViewCommand(app),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : cslam::kExitConfigError;
  }
  spdlog::set_default_logger(spdlog::stderr_color_mt("app"));
  spdlog::set_level(spdlog::level::from_str(log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  // Ceres reports through glog, and its warnings ("linear solver failure" when LM meets a
  // rank-deficient step and retries with more damping) are routine in cluster solves: a user
  // sees them only when asking for the debug log.
  FLAGS_minloglevel = spdlog::get_level() <= spdlog::level::debug ? google::GLOG_INFO
                                                                   : google::GLOG_ERROR;

  for (const auto& cmd : commands) {
    if (!cmd.sub->parsed()) continue;
    try {
      return cmd.run();
    } catch (const cslam::Error& e) {
      std::fprintf(stderr, "cslam %s: error: %s\n", cmd.sub->get_name().c_str(), e.what());
      return e.exit_code();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cslam %s: internal error: %s\n", cmd.sub->get_name().c_str(), e.what());
      return cslam::kExitInternalError;
    }
  }
  return cslam::kExitConfigError;
}
