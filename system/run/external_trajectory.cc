#include "system/run/external_trajectory.h"

#include <filesystem>

#include "core/errors.h"
#include "system/eval/trajectory_evaluation.h"
#include "system/eval/trajectory_io.h"
#include "system/eval/trajectory_metrics.h"
#include "system/pipeline/run_input.h"

namespace cslam {

namespace fs = std::filesystem;

void ExternalTrajectoryOptions::Check() const {
  if (input.empty()) throw ConfigError("external trajectory: no input named for its ground truth");
  if (trajectory.empty()) throw ConfigError("external trajectory: no trajectory file");
  if (!format.empty() && format != "kitti" && format != "tum")
    throw ConfigError("external trajectory: format must be kitti or tum, got '" + format + "'");
  if (max_frames < 0) throw ConfigError("external trajectory: max_frames must be >= 0");
}

Trajectory InputGroundTruth(const std::string& input, int max_frames) {
  InputOptions o;
  o.max_frames = max_frames;
  o.use_images = false;
  const RunInput in = OpenRunInput(input, o);
  if (!in.gt_world_from_cam || in.gt_world_from_cam->empty())
    throw InputError(input, "has no ground-truth camera poses to score a trajectory against");
  Trajectory gt;
  const int n = std::min<int>(in.num_frames(), static_cast<int>(in.gt_world_from_cam->size()));
  for (int f = 0; f < n; ++f) {
    gt.frames.push_back(f);
    gt.poses.push_back((*in.gt_world_from_cam)[f]);
    gt.timestamps.push_back(in.timestamps[f]);
  }
  return gt;
}

Trajectory ReadExternalTrajectory(const ExternalTrajectoryOptions& options, const Trajectory& gt) {
  options.Check();
  const TrajectoryFormat format = options.format == "kitti" ? TrajectoryFormat::kKitti
                                  : options.format == "tum" ? TrajectoryFormat::kTum
                                                            : GuessTrajectoryFormat(options.trajectory);
  Trajectory est = ReadTrajectory(options.trajectory, format);
  if (est.empty()) throw InputError(options.trajectory, "holds no pose");
  if (format == TrajectoryFormat::kTum) {
    if (!options.frames.empty())
      throw InputError(options.frames, "a frames list applies to KITTI-format files; " +
                                           options.trajectory + " is TUM (paired by timestamp)");
    est.frames.clear();
  } else {
    const bool side_file = fs::exists(FrameIndexPathFor(options.trajectory));
    if (!options.frames.empty()) {
      std::vector<int> frames = ReadFrameIndices(options.frames);
      if (frames.size() != est.size())
        throw InputError(options.frames, "lists " + std::to_string(frames.size()) +
                                             " frames but " + options.trajectory + " has " +
                                             std::to_string(est.size()) + " poses");
      est.frames = std::move(frames);
    } else if (!side_file && est.size() != gt.size()) {
      throw InputError(options.trajectory,
                       "has " + std::to_string(est.size()) + " poses but the input has " +
                           std::to_string(gt.size()) +
                           " frames; a KITTI-format trajectory without a frames list must have "
                           "one line per frame (give 'frames:' or use TUM format)");
    }
    est.timestamps.clear();
  }
  AssociationOptions association;
  const TrajectoryAssociation pairs = Associate(gt, est, association);
  if (pairs.size() < 3)
    throw InputError(options.trajectory,
                     "only " + std::to_string(pairs.size()) + " of its " +
                         std::to_string(est.size()) +
                         " poses pair with the ground truth (by " +
                         (format == TrajectoryFormat::kTum ? "timestamp" : "frame index") +
                         "); at least 3 are needed");
  return est;
}

RunMetrics ScoreExternalTrajectory(const ExternalTrajectoryOptions& options,
                                   const std::string& system) {
  const Trajectory gt = InputGroundTruth(options.input, options.max_frames);
  const Trajectory est = ReadExternalTrajectory(options, gt);
  RunMetrics m;
  m.sequence = fs::path(options.input).filename().string();
  m.frames = static_cast<int>(gt.size());
  m.method = system;
  m.camera = EvaluateCameraTrajectory(gt, est);
  return m;
}

}  // namespace cslam
