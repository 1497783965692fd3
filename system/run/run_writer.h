#pragma once
// Writes the outputs of a run (docs/architecture.md "Outputs of one run") from its map state
// and the trajectories built from it. Every file goes through a temporary name and a rename,
// so an interrupted or failed run leaves complete files only.
#include <string>

#include "system/eval/metrics_json.h"
#include "system/pipeline/pipeline.h"
#include "system/pipeline/run_input.h"
#include "system/run/run_trajectories.h"

namespace cslam {

/// Writes `trajectories` (KITTI + TUM; camera_trajectory_gt.* with the ground truth of the same
/// frames when the input has one), objects/, clusters.csv, landmarks.ply/.pcd,
/// render/trajectory.png (RenderRunTrajectoryPlot), config.yaml and (when given) metrics.json into
/// `out_dir`.
void WriteRunOutputs(const RunInput& input, const PipelineResult& result,
                     const RunTrajectories& trajectories, const PipelineOptions& options,
                     const std::string& out_dir, const RunMetrics* metrics);

}  // namespace cslam
