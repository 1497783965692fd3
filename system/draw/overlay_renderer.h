#pragma once
// render/overlay_NNNNNN.png: the left image with each tracked keypoint coloured by its cluster
// and a short trail of its recent positions.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "system/draw/render_scene.h"

namespace cslam {

/// The grey left image as BGR with every track's trail as an anti-aliased polyline in its
/// cluster colour and a filled dot at its newest position. Moving clusters are drawn over
/// static and unclustered tracks. `left_grey` may be CV_8UC1 or CV_8UC3 (BGR).
cv::Mat RenderOverlay(const cv::Mat& left_grey, const std::vector<OverlayTrack>& tracks);

/// Draws, top left, a legend of the clusters of `tracks` with their keypoint counts: "static",
/// "outlier", and "object <id>" with the id of objects/index.csv.
void DrawOverlayLegend(cv::Mat& image, const std::vector<OverlayTrack>& tracks);

}  // namespace cslam
