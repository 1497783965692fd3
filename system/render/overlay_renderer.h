#pragma once
// render/overlay_NNNNNN.png: the left image with each tracked keypoint coloured by its cluster
// and a short trail of its recent positions.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace cslam {

/// One track to draw on the overlay.
struct OverlayTrack {
  int cluster = -1;                     ///< ColorForCluster id
  std::vector<Eigen::Vector2d> trail;   ///< left-image pixels, oldest .. newest (current)
};

/// The grey left image as BGR with every track's trail as an anti-aliased polyline in its
/// cluster colour and a filled dot at its newest position. Moving clusters are drawn over
/// static and unclustered tracks. `left_grey` may be CV_8UC1 or CV_8UC3 (BGR).
cv::Mat RenderOverlay(const cv::Mat& left_grey, const std::vector<OverlayTrack>& tracks);

}  // namespace cslam
