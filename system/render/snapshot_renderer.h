#pragma once
// render/snapshot_NNNNNN.png: a perspective view from behind and above the camera of the
// clustered landmarks (coloured by cluster), the camera frustum and the recent trajectories.
#include <opencv2/core.hpp>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "system/render/dense_cloud.h"
#include "system/draw/render_scene.h"
#include "system/render/render_view.h"

namespace cslam {

/// Options of the snapshot pictures.
struct SnapshotOptions {
  int width = 1280, height = 720;     ///< picture size, px
  double horizontal_fov_deg = 80.0;   ///< field of view of the virtual camera, degrees, (0, 170)
  double back_m = 10.0;               ///< viewpoint distance behind the camera, metres, >= 0
  double up_m = 8.0;                  ///< viewpoint height above the camera, metres
  double look_ahead_m = 12.0;         ///< the view aims at this point ahead of the camera, metres, > 0
  double far_m = 200.0;               ///< nothing farther from the viewpoint is drawn, metres
  double landmark_size_px = 6.0;      ///< diameter of a landmark dot, px, > 0
  double dense_point_size_px = 2.0;   ///< diameter of a dense stereo point, px, > 0
  double frustum_depth_m = 2.0;       ///< length of the drawn camera frustum, metres, > 0
  double ground_below_m = 1.65;       ///< ground grid this far below the camera (KITTI: 1.65 m); <= 0: none
  double grid_step_m = 5.0;           ///< ground grid spacing, metres, > 0
  double grid_extent_m = 60.0;        ///< ground grid half-size around the camera, metres, > 0
  int supersampling = 2;              ///< render this many times larger and average (anti-aliasing), 1..4
  DenseCloudOptions dense;            ///< for RenderDenseSnapshot

  void Check() const;
  void Load(OptionsReader& reader);
};

/// The virtual camera of a snapshot of a camera at `world_from_cam`: behind it by back_m, above
/// it by up_m (camera -y), looking at the point look_ahead_m in front of it.
RenderView SnapshotView(const Pose& world_from_cam, const SnapshotOptions& options);

/// Draws `points` (coloured by ColorForCluster), the frustum of `cam` at `world_from_cam`, the
/// `recent` trajectories (camera black, ground truth dashed), a ground grid and a legend of
/// the clusters shown. Returns an 8-bit BGR image of options.width x options.height. Renders
/// in its own OffscreenContext, so calls may run concurrently on different threads.
/// Throws ConfigError for bad options, cslam::Error when offscreen rendering fails.
cv::Mat RenderSnapshot(const std::vector<RenderPoint>& points, const Pose& world_from_cam,
                       const StereoCamera& cam, const std::vector<RenderTrajectory>& recent,
                       const SnapshotOptions& options);

/// RenderSnapshot plus the dense cloud of this frame's stereo pair (LabelDenseCloud with
/// options.dense) drawn as small dots under the landmarks.
cv::Mat RenderDenseSnapshot(const std::vector<RenderPoint>& points, const Pose& world_from_cam,
                            const StereoCamera& cam, const std::vector<RenderTrajectory>& recent,
                            const cv::Mat& left, const cv::Mat& right,
                            const SnapshotOptions& options);

}  // namespace cslam
