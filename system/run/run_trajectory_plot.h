#pragma once
// render/trajectory.png of a run, drawn from its outputs (RunOutputs): the one function both
// the run writer and `cslam render` call, so a re-render of an untouched run gives the same
// picture.
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "system/draw/render_scene.h"
#include "system/run/run_outputs.h"

namespace cslam {

/// Which clusters the plot draws. An online map of a real drive holds dozens of short-lived
/// fragments whose lines hide the few objects that matter; every cluster stays in the output
/// files, the plot only counts the small ones in its legend.
struct TrajectoryPlotOptions {
  int min_poses = 10;      ///< a cluster needs this many poses to be drawn (>= 2: a line)
  int min_landmarks = 15;  ///< ... and this many landmarks in landmarks.ply (0: any)
};

/// The camera's path (`camera`'s positions) from `first_frame` to `last_frame` into `line`,
/// broken where tracking was lost (frames without a pose).
RenderTrajectory CameraPathLine(const Trajectory& camera, RenderTrajectory line,
                                int first_frame = 0,
                                int last_frame = std::numeric_limits<int>::max());

/// Each cluster that passes `options` as the path of its landmarks' centroid, broken at frames
/// without a pose, labelled with its points and frame span, biggest cluster first. A cluster
/// straying more than 100 m beyond the camera's own extent is left out with a warning in the
/// log naming `picture`. `too_small` counts the clusters `options` left out.
std::vector<RenderTrajectory> ClusterTrackLines(const RunOutputs& outputs,
                                                const TrajectoryPlotOptions& options,
                                                const std::string& picture, int* too_small);

/// The lines of the plot: the ground truth (dashed, when there is one), the camera, and each
/// cluster that passes `options` as the path of its landmarks' centroid, biggest cluster
/// first. A cluster straying more than 100 m beyond the camera's own extent is left out with a
/// warning in the log. When clusters were too small to draw, a last line without positions
/// carries the legend entry that counts them.
std::vector<RenderTrajectory> RunTrajectoryPlotLines(const RunOutputs& outputs,
                                                     const TrajectoryPlotOptions& options = {});

/// RenderTrajectoryTopView of RunTrajectoryPlotLines. Throws cslam::Error when offscreen
/// rendering is unavailable.
cv::Mat RenderRunTrajectoryPlot(const RunOutputs& outputs, int width = 1200, int height = 900,
                                const TrajectoryPlotOptions& options = {});

}  // namespace cslam
