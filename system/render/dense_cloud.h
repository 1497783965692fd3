#pragma once
// Dense clustered cloud of one frame (beyond the paper, for pictures only): StereoSGBM
// disparities back-projected to 3-D, voxel-grid downsampled, and every point given the
// cluster of its nearest clustered landmark.
#include <opencv2/core.hpp>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "system/draw/render_scene.h"

namespace cslam {

/// Options of LabelDenseCloud.
struct DenseCloudOptions {
  int num_disparities = 96;   ///< SGBM disparity search range, px, a positive multiple of 16
  int block_size = 5;         ///< SGBM matching block side, px, odd, >= 1
  double min_depth_m = 1.0;   ///< closer stereo points are dropped, metres
  double max_depth_m = 30.0;  ///< farther stereo points are dropped (too noisy), metres
  double voxel_size_m = 0.15; ///< voxel-grid leaf size, metres, > 0
  /// A dense point farther than this from every clustered landmark stays unclustered (-1).
  double max_assign_distance_m = 1.5;

  void Check() const;
  void Load(OptionsReader& reader);
};

/// Counts of what LabelDenseCloud did, for logs and tests.
struct DenseCloudStats {
  int stereo_points = 0;      ///< valid disparities within the depth range
  int downsampled_points = 0; ///< after the voxel grid
  int labelled_points = 0;    ///< given a cluster (>= 0)
};

/// Dense world-frame points of the rectified grey stereo pair `left`/`right` (same size,
/// CV_8UC1, matching `cam`) seen from `world_from_cam`. Each takes the cluster of the nearest
/// landmark with cluster >= 0 within max_assign_distance_m, else -1. Throws ConfigError for
/// bad options and InputError when the images do not match each other or the camera.
std::vector<RenderPoint> LabelDenseCloud(const cv::Mat& left, const cv::Mat& right,
                                         const StereoCamera& cam, const Pose& world_from_cam,
                                         const std::vector<RenderPoint>& landmarks,
                                         const DenseCloudOptions& options,
                                         DenseCloudStats* stats = nullptr);

}  // namespace cslam
