#pragma once
// render/trajectory.png: the top view (world x to the right, world z upwards in the picture)
// of the camera and cluster trajectories, with a labelled metric grid, a scale bar and a
// legend. The world frame is the first camera frame (x right, y down, z forward).
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "system/draw/render_scene.h"

namespace cslam {

/// Where world points land in the top view: u = origin_u + scale * x, v = origin_v - scale * z
/// (pixel (0,0) is the centre of the top-left pixel). y (height) is ignored.
struct TopViewLayout {
  double scale_px_per_m = 1.0;
  double origin_u = 0.0, origin_v = 0.0;  ///< pixel of the world origin
  int plot_left = 0, plot_top = 0, plot_right = 0, plot_bottom = 0;  ///< plot area, px
  double grid_step_m = 1.0;  ///< spacing of the labelled grid lines
  /// The legend box: in a plot corner that no trajectory crosses, else in a column beside the
  /// plot (which then narrows). Empty when no trajectory has a label.
  cv::Rect legend;
  /// The scale bar's white box: in the plot corner with the fewest trajectory pixels.
  cv::Rect scale_bar;

  Eigen::Vector2d ToPixel(const Eigen::Vector3d& p_world) const {
    return {origin_u + scale_px_per_m * p_world.x(), origin_v - scale_px_per_m * p_world.z()};
  }
};

/// The layout RenderTrajectoryTopView uses: every position fits in the plot area with equal
/// scales on both axes, centred, with a small margin, and the legend covers no trajectory.
TopViewLayout ComputeTopViewLayout(const std::vector<RenderTrajectory>& trajectories, int width,
                                   int height);

/// The title RenderTrajectoryTopView writes above the plot unless given another.
inline constexpr const char* kTopViewTitle =
    "Trajectories, top view (x-z plane of the first camera frame)";

/// Draws the trajectories (each in TrajectoryColor: camera black, clusters in ColorForCluster,
/// ground truth dashed) on white with the grid, axis labels in metres, a scale bar, a legend of
/// the labels and `title` above. Returns an 8-bit BGR image. Renders in its own
/// OffscreenContext, so calls may run concurrently on different threads. Throws cslam::Error
/// when offscreen rendering is unavailable.
cv::Mat RenderTrajectoryTopView(const std::vector<RenderTrajectory>& trajectories, int width = 1200,
                                int height = 900, const std::string& title = kTopViewTitle);

}  // namespace cslam
