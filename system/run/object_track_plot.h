#pragma once
// render/objects.png: the top view of every reported object's track (objects/<id>.txt through
// its landmarks' centroid, in its id's colour as in objects/index.csv and every other picture),
// zoomed on the objects: each matched object's ground truth dashed over the frames the object
// was tracked, the camera faint over the same frames for context, and a legend of each object's
// id, frames and motion error per frame (ME_r, ME_t from metrics.json). Drawn from the final
// outputs by the run and again by `cslam render`.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "system/draw/render_scene.h"
#include "system/eval/metrics_json.h"
#include "system/run/run_outputs.h"

namespace cslam {

/// The lines of the picture, in drawing and legend order: the camera (kContextPath) over the
/// frames from the first object's first to the last object's last, each object by id (label
/// "object 3 (Van), frames 10-80: ME_r 0.42 deg, ME_t 0.081 m", the class being the matched
/// labelled object's when it has one; "...: truth id 7, no motion error"
/// when matched without errors; "...: no labelled object matched" when the run had labels but
/// none for it), then the ground truth of each object matched to a labelled one (metrics.json's
/// matching, else objects_gt/index.csv's) over that object's frames (dashed, unlabelled), and
/// legend-only lines that name the dashed lines and count labelled objects not found.
/// `metrics` may be null (no metrics.json): no errors in the legend.
std::vector<RenderTrajectory> ObjectTrackPlotLines(const RunOutputs& outputs,
                                                   const RunMetrics* metrics);

/// RenderTrajectoryTopView of ObjectTrackPlotLines under the title "Object tracks, top view",
/// with each object's id written beside the start of its track.
/// Throws cslam::Error when offscreen rendering is unavailable.
cv::Mat RenderObjectTrackPlot(const RunOutputs& outputs, const RunMetrics* metrics,
                              int width = 1200, int height = 900);

/// Reads `out_dir`/metrics.json when there is one and writes `out_dir`/render/objects.png;
/// returns its path. Throws InputError naming metrics.json when it is malformed.
std::string WriteObjectTrackPlot(const RunOutputs& outputs, const std::string& out_dir,
                                 int width = 1200, int height = 900);

}  // namespace cslam
