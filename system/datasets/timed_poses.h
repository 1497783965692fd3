#pragma once
// Ground-truth trajectories of a rig's body frame as the datasets give them, with timestamps
// in seconds, and their interpolation at the images' times (docs/formats.md "Ground truth of
// a stereo rig").
#include <string>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// world_from_body poses at increasing times (seconds), and the file they came from.
struct TimedPoses {
  std::string path;
  std::vector<double> times;
  std::vector<Pose> world_from_body;
};

/// TUM format: "t tx ty tz qx qy qz qw" per line (seconds), '#' lines and blank lines skipped.
TimedPoses ReadTumPoses(const std::string& path);

/// EuRoC `state_groundtruth_estimate0/data.csv` or TUM-VI `mocap0/data.csv`: comma-separated
/// "timestamp_ns, px, py, pz, qw, qx, qy, qz[, ...]", '#' header lines skipped.
TimedPoses ReadAslPoses(const std::string& path);

/// The poses at `times` (seconds, same clock), interpolated between the two nearest samples
/// (slerp). Throws InputError naming the file when a time lies outside the poses' span by
/// more than `tolerance_s`, or between two samples more than `max_gap_s` apart.
std::vector<Pose> InterpolatePoses(const TimedPoses& poses, const std::vector<double>& times,
                                   double tolerance_s = 0.002, double max_gap_s = 0.5);

}  // namespace cslam
