#pragma once
// The configuration `cslam run` uses for an input when no --config is given: the project's
// recommended settings for that kind of input (configs/kitti_raw.yaml for KITTI raw drives,
// configs/kitti_odometry.yaml for KITTI odometry sequences), compiled in from those files.
// Their `output` section is not applied (renders stay off unless asked for).
#include <optional>
#include <string>

#include "system/pipeline/run_input.h"

namespace cslam {

/// A configuration file's name and text.
struct BuiltinConfig {
  std::string name;  ///< "configs/kitti_raw.yaml"
  std::string yaml;
};

/// The recommended configuration for `input_kind` (RunInput::kind); nullopt where the
/// built-in defaults are the recommendation (synthetic sequences).
std::optional<BuiltinConfig> BuiltinConfigFor(InputKind input_kind);

}  // namespace cslam
