#pragma once
// render/trajectory.png of a run, drawn from its outputs (RunOutputs): the one function both
// the run writer and `cslam render` call, so a re-render of an untouched run gives the same
// picture.
#include <opencv2/core.hpp>
#include <vector>

#include "system/render_scene.h"
#include "system/run_outputs.h"

namespace cslam {

/// The lines of the plot: the ground truth (dashed, when there is one), the camera, and each
/// cluster with at least two poses as the path of its landmarks' centroid. A cluster straying
/// more than 100 m beyond the camera's own extent is left out with a warning in the log.
std::vector<RenderTrajectory> RunTrajectoryPlotLines(const RunOutputs& outputs);

/// RenderTrajectoryTopView of RunTrajectoryPlotLines. Throws cslam::Error when offscreen
/// rendering is unavailable.
cv::Mat RenderRunTrajectoryPlot(const RunOutputs& outputs, int width = 1200, int height = 900);

}  // namespace cslam
