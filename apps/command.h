#pragma once
// Each subcommand lives in its own apps/<name>_command.cc: Add<Name>Command registers the
// CLI11 subcommand and its flags and returns the function that runs it after parsing.
#include <CLI/CLI.hpp>

#include <functional>
#include <memory>

namespace cslam::apps {

/// A registered subcommand: `run` is called when `sub` was the one given; returns the exit code.
struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;
};

// One declaration per subcommand file, in the order `cslam --help` lists them.
Command AddEvalCommand(CLI::App& app);

/// `cslam synth`: generates a synthetic ground-truth sequence (system/synthetic/synthetic_scene.h).
Command AddSynthCommand(CLI::App& app);
Command AddRunCommand(CLI::App& app);
/// `cslam demo`: the embedded synthetic default.
Command AddDemoCommand(CLI::App& app);
/// `cslam bench`: every backend method on a generated synthetic suite (Table 1).
Command AddBenchCommand(CLI::App& app);
/// `cslam render OUT`: the pictures of a finished run, drawn again from its output files.
Command AddRenderCommand(CLI::App& app);
/// `cslam calib check INPUT`: does a rig's calibration rectify its images (docs/own_rig.md).
Command AddCalibCommand(CLI::App& app);
/// `cslam view OUT`: OUT/view.html, the run in one self-contained page.
Command AddViewCommand(CLI::App& app);

}  // namespace cslam::apps
