#pragma once
// Writes the outputs of a run (docs/architecture.md "Outputs of one run") from its map state
// and the trajectories built from it. Every file goes through a temporary name and a rename,
// so an interrupted or failed run leaves complete files only.
#include <string>
#include <vector>

#include "system/eval/metrics_json.h"
#include "system/pipeline/pipeline.h"
#include "system/pipeline/run_input.h"
#include "system/run/run_outputs.h"
#include "system/run/run_trajectories.h"
#include "system/runtime/resource_log.h"

namespace cslam {

/// Writes `trajectories` (KITTI + TUM; camera_trajectory_gt.* with the ground truth of the same
/// frames when the input has one), objects/, clusters.csv, landmarks.ply/.pcd, windows.csv,
/// resources.csv, config.yaml and (when given) metrics.json into `out_dir`; no picture, so
/// nothing a renderer does can lose them. Returns what the pictures are drawn from.
RunOutputs WriteRunOutputs(const RunInput& input, const PipelineResult& result,
                           const RunTrajectories& trajectories, const PipelineOptions& options,
                           const std::string& out_dir, const RunMetrics* metrics);

/// Frames of a final-state overlay's keypoint trails (as the online overlays).
inline constexpr int kOverlayTrailFrames = 6;

/// Draws the run's pictures from its final outputs into `out_dir`/render: trajectory.png
/// (RenderRunTrajectoryPlot), objects.png (WriteObjectTrackPlot, with the metrics.json already
/// in `out_dir`), resources.png, and with `input` (its camera and images) the
/// final-state snapshots and overlays of system/run/final_pictures.h, as options.output asks.
/// A picture that cannot be drawn or written does not stop the others; returns one line per
/// picture not written ("render/trajectory.png: why").
std::vector<std::string> WriteRunPictures(const RunOutputs& outputs,
                                          const std::vector<ResourceSample>& resources,
                                          const PipelineOptions& options, const std::string& out_dir,
                                          const RunInput* input = nullptr);

}  // namespace cslam
