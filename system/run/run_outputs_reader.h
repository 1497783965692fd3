#pragma once
// Reads back what a finished `cslam run` (or `cslam demo`) wrote into its output folder
// (docs/usage.md), as far as the pictures need it: camera_trajectory.txt (required),
// camera_trajectory_gt.txt (when present), objects/index.csv with objects/<id>.txt,
// clusters.csv, and overlay_keypoints.csv (when present).
#include <string>

#include "system/run/run_outputs.h"

namespace cslam {

/// Reads the outputs in `out_dir`. Throws InputError naming the file (and line) and what was
/// expected: a missing folder or camera trajectory, a malformed line (field count, a number
/// that is not one, a wrong header), a cluster trajectory whose pose count disagrees with
/// objects/index.csv, a landmark of a moving cluster that has no trajectory.
RunOutputs ReadRunOutputs(const std::string& out_dir);

}  // namespace cslam
