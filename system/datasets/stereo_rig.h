#pragma once
// A user's stereo rig as calibrated, before rectification (docs/own_rig.md): two cameras with
// their lens models and the rigid transform between them, whatever file it was read from.
#include <optional>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/rigid.h"

namespace cslam {

/// Lens distortion models the rectification supports (OpenCV's plain and fisheye models).
enum class LensModel {
  kNone,              ///< ideal pinhole
  kRadialTangential,  ///< k1 k2 p1 p2 [k3] (Kalibr "radtan", OpenCV's default model)
  kEquidistant,       ///< k1 k2 k3 k4 (Kalibr "equidistant", OpenCV fisheye, Kannala-Brandt)
};
/// Kalibr's words for the models, used in rig.yaml and in messages.
inline constexpr EnumName<LensModel> kLensModelNames[] = {
    {LensModel::kNone, "none"},
    {LensModel::kRadialTangential, "radtan"},
    {LensModel::kEquidistant, "equidistant"},
};

/// One camera's pinhole intrinsics and lens distortion, in pixels of its own raw image.
struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  LensModel lens = LensModel::kNone;
  std::vector<double> distortion;  ///< the model's coefficients, in the order above

  /// True when any distortion coefficient is not zero.
  bool HasDistortion() const;
};

/// Two calibrated cameras, cam0 the left one. cam1_from_cam0 maps points from cam0's frame
/// into cam1's (Kalibr's T_cn_cnm1 of cam1, OpenCV's [R|T]); metres.
struct StereoRig {
  std::string source;  ///< the calibration file(s) read, for messages
  std::string format;  ///< "euroc", "kalibr", "opencv" or "orbslam3"
  CameraIntrinsics cam0, cam1;
  Pose cam1_from_cam0 = Pose::Identity();
  std::optional<Pose> body_from_cam0;  ///< EuRoC T_BS of cam0 / Kalibr T_cam_imu⁻¹, when given
  /// A rectification the file itself gives (OpenCV R1 R2 P1 P2), used instead of computing one.
  struct GivenRectification {
    Eigen::Matrix3d r0, r1;                    ///< rectified camera i ← raw camera i
    Eigen::Matrix<double, 3, 4> p0, p1;        ///< rectified projections
  };
  std::optional<GivenRectification> given_rectification;

  /// Distance between the camera centres, metres.
  double Baseline() const { return cam1_from_cam0.translation().norm(); }
};

/// The cheap geometric checks `cslam run` and `cslam calib check` make before any image is
/// read. Throws InputError naming rig.source with the likely mistake as a hint:
/// a baseline outside 0.01–2 m ("millimetres?"), a translation not mostly along x or pointing
/// the wrong way ("T looks inverted: Kalibr's T_cn_cnm1 maps cam0 to cam1"), the two cameras
/// with different lens models, a camera without a positive focal length or image size.
void CheckStereoRig(const StereoRig& rig);

}  // namespace cslam
