#pragma once
// render/resources.png: a run's resident memory and frame rate against the frame number, drawn
// from the samples of system/runtime/resource_log.h when the run's outputs are written (and
// again by `cslam render` from resources.csv).
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "system/runtime/resource_log.h"

namespace cslam {

/// The chart of render/resources.png (needs at least two samples).
cv::Mat RenderResourceChart(const std::vector<ResourceSample>& samples);

/// Writes RenderResourceChart as out_dir/render/resources.png. Fewer than two samples: nothing
/// is written, as for resources.csv.
void WriteResourceChart(const std::vector<ResourceSample>& samples, const std::string& out_dir);

}  // namespace cslam
