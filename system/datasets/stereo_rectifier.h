#pragma once
// Rectification of a calibrated stereo rig, computed once per run (OpenCV stereoRectify /
// initUndistortRectifyMap, or their cv::fisheye versions) and applied to every pair: what turns
// a user's raw rig into the rectified pinhole StereoCamera the rest of the system consumes.
#include <opencv2/core/mat.hpp>

#include <Eigen/Core>
#include <string>

#include "core/stereo_camera.h"
#include "system/datasets/stereo_rig.h"

namespace cslam {

/// How the rectified image is framed.
struct RectificationOptions {
  /// Zoom in (about the principal point, in steps of zoom_step) until no rectified pixel
  /// samples outside the raw images. Off: OpenCV's alpha 0 / balance 0 framing as it is.
  bool exclude_invalid_pixels = true;
  double zoom_step = 0.005;  ///< relative focal-length step, in (0, 0.1]
  void Check() const;
};

/// The rectifying maps of one rig and the rectified camera they produce.
class StereoRectifier {
 public:
  /// Builds the maps for `rig` (which must pass CheckStereoRig). The rectified image keeps
  /// the raw size; its focal length is chosen so that every rectified pixel of both images
  /// comes from inside the raw image (OpenCV alpha 0; fisheye: the balance-0 focal length;
  /// either enlarged until no invalid pixel is left, see RectificationOptions). A rig that is already rectified (no
  /// distortion, no rotation, identical intrinsics, translation along x) gets no maps: its
  /// images pass through untouched, bit for bit.
  explicit StereoRectifier(const StereoRig& rig, const RectificationOptions& options = {});

  /// The rectified pinhole stereo camera (left = rectified cam0).
  const StereoCamera& camera() const { return camera_; }
  /// Rectified cam0 ← raw cam0 and rectified cam1 ← raw cam1 (rotations).
  const Eigen::Matrix3d& rect0_from_cam0() const { return rect0_from_cam0_; }
  const Eigen::Matrix3d& rect1_from_cam1() const { return rect1_from_cam1_; }
  /// True when the pair passes through unchanged (see the constructor).
  bool identity() const { return identity_; }

  /// Rectifies a raw pair (8-bit grey, the rig's size; checked by the caller).
  void Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_out, cv::Mat* right_out) const;

  /// rectified.yaml: fx, fy, cx, cy, baseline, width, height and both rectifying rotations.
  std::string RectifiedYamlText() const;

 private:
  void Build(const StereoRig& rig, const RectificationOptions& options);

  StereoCamera camera_;
  Eigen::Matrix3d rect0_from_cam0_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rect1_from_cam1_ = Eigen::Matrix3d::Identity();
  bool identity_ = false;
  cv::Mat map0x_, map0y_, map1x_, map1y_;
};

}  // namespace cslam
