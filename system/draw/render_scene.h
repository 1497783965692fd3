#pragma once
// Plain data the renderers and exporters take: no backend types, so the pictures can be drawn
// from any source (the online map, a batch result, a synthetic scene, a test).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace cslam {

/// One landmark (or dense point) in the world frame with its cluster id (0 static, >= 1
/// moving, -1 unclustered).
struct RenderPoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< world frame, metres
  int cluster = -1;
};

/// A trajectory to draw: positions in the world frame, oldest first.
struct RenderTrajectory {
  std::string label;                          ///< legend text
  /// World frame, metres; a non-finite position breaks the line (frames with no pose).
  std::vector<Eigen::Vector3d> positions;
  int cluster = -1;    ///< -1: the camera (black); otherwise the cluster whose colour to use
  bool dashed = false; ///< ground truth is drawn dashed
};

/// One keypoint track to draw on an overlay.
struct OverlayTrack {
  int cluster = -1;                     ///< ColorForCluster id
  std::vector<Eigen::Vector2d> trail;   ///< left-image pixels, oldest .. newest (current)
};

}  // namespace cslam
