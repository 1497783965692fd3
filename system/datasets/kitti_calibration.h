#pragma once
// Parsers for KITTI calibration files. All of them read "key: numbers" lines through
// KeyValueFile, which keeps line numbers so every error names the file and line.
#include <Eigen/Core>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"

namespace cslam {

/// A text file of "key: value" lines; values are parsed as numbers on request.
class KeyValueFile {
 public:
  /// Reads `path`. Throws InputError when the file cannot be read, a non-empty line has no
  /// "key:" or a key appears twice.
  static KeyValueFile Read(const std::string& path);

  const std::string& path() const { return path_; }
  bool Has(const std::string& key) const { return entries_.count(key) > 0; }
  /// Line number (1-based) of `key`, 0 when absent.
  int LineOf(const std::string& key) const;
  /// Exactly `count` finite numbers of `key`. Throws InputError naming the file and line when
  /// the key is missing, a value is not a number or the count differs.
  std::vector<double> Numbers(const std::string& key, int count) const;
  /// Numbers(key, rows * cols) as a row-major matrix.
  Eigen::MatrixXd Matrix(const std::string& key, int rows, int cols) const;

 private:
  struct Entry {
    std::string value;
    int line = 0;
  };
  std::string path_;
  std::map<std::string, Entry> entries_;
};

/// The rectified-camera part of KITTI raw `calib_cam_to_cam.txt`.
struct KittiCamToCam {
  std::string path;
  Eigen::Matrix3d r_rect_00 = Eigen::Matrix3d::Identity();  ///< cam0 → rectified cam0
  /// P_rect_xx (3×4) and S_rect_xx (width, height) for the cameras the file lists.
  std::array<std::optional<Eigen::Matrix<double, 3, 4>>, 4> p_rect;
  std::array<std::optional<Eigen::Vector2i>, 4> s_rect;
  std::array<int, 4> p_rect_line{};  ///< line of P_rect_xx, for errors
};

/// Reads `calib_cam_to_cam.txt`: R_rect_00 is required, P_rect_xx / S_rect_xx are read when
/// present (and must then be well-formed).
KittiCamToCam ReadKittiCamToCam(const std::string& path);

/// Rectified stereo camera of the pair (left, right) ∈ {(0,1), (2,3)}: intrinsics from
/// P_rect_left, baseline = x-offset difference (K⁻¹·P_left[:,3] − K⁻¹·P_right[:,3]).x with
/// K = P_left[:, 0:3] (= (P_left[0,3] − P_right[0,3]) / fx for the grey pair; 0.532712 m, not
/// 0.532725 m, for the colour pair), size from S_rect_left. Throws
/// InputError naming the file and line for a missing camera, fx/fy <= 0 or baseline <= 0.
StereoCamera StereoCameraFromCamToCam(const KittiCamToCam& calib, int left, int right);

/// Offset of rectified camera `cam` from rectified camera 00: cam_from_cam0rect is a pure
/// translation K⁻¹·P_rect_xx[:,3] (K = P_rect_xx[:, 0:3]).
Pose CamFromCam0Rect(const KittiCamToCam& calib, int cam);

/// Reads a rigid transform file with `R:` (9 numbers, row-major) and `T:` (3 numbers), e.g.
/// calib_velo_to_cam.txt (returns cam_from_velo) or calib_imu_to_velo.txt (velo_from_imu).
Pose ReadKittiRigidCalibration(const std::string& path);

/// KITTI odometry `calib.txt`.
struct KittiOdometryCalib {
  Eigen::Matrix<double, 3, 4> p0, p1;
  std::optional<Pose> cam0_from_velo;  ///< from "Tr:" when present
  StereoCamera camera;                 ///< from P0/P1; width/height left 0
};

/// Reads `calib.txt` (P0, P1 required; Tr optional). Throws InputError naming the file and
/// line on malformed lines, fx/fy <= 0 or baseline <= 0.
KittiOdometryCalib ReadKittiOdometryCalibration(const std::string& path);

/// A 3×4 [R | t] as a pose, the rotation projected onto SO(3) (files store ~7 digits).
Pose PoseFrom3x4(const Eigen::Matrix<double, 3, 4>& m);

}  // namespace cslam
