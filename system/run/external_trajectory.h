#pragma once
// Another system's camera trajectory scored as a `cslam run` is: against the ground truth of
// the same input, with the same association and the same metrics (EvaluateCameraTrajectory),
// so peers sit in the suite's table beside our runs.
#include <string>

#include "system/eval/metrics_json.h"
#include "system/eval/trajectory.h"

namespace cslam {

/// What to score.
struct ExternalTrajectoryOptions {
  std::string input;       ///< dataset folder holding the ground truth
  int max_frames = 0;      ///< the ground truth cut to its first N frames (0 = all)
  std::string trajectory;  ///< the estimate's file
  std::string format;      ///< "kitti" | "tum" | "" (guessed from the first data line)
  std::string frames;      ///< a frames list: one frame index a line, one line per pose ("" = none)
  /// Throws ConfigError naming the field.
  void Check() const;
};

/// The input's ground-truth camera trajectory, one pose per frame with its frame index and
/// timestamp: exactly the one `cslam run` scores against. Throws InputError when the input
/// has no ground truth.
Trajectory InputGroundTruth(const std::string& input, int max_frames);

/// Reads the estimate and associates it: a TUM file by timestamp (the input's timestamps), a
/// KITTI file by its frames list (options.frames, or the side file FrameIndexPathFor) or,
/// without either, line k = frame k, which needs exactly one line per ground-truth frame.
/// Throws InputError naming the file and line: a wrong format, a wrong line count, a frames
/// list that does not match, fewer than 3 poses that pair with the ground truth.
Trajectory ReadExternalTrajectory(const ExternalTrajectoryOptions& options, const Trajectory& gt);

/// metrics.json's camera section (and sequence, frames, method = `system`) for the estimate.
RunMetrics ScoreExternalTrajectory(const ExternalTrajectoryOptions& options,
                                   const std::string& system);

}  // namespace cslam
