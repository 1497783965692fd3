#pragma once
// Readers of the calibration files users already have, each giving a StereoRig
// (docs/own_rig.md, docs/formats.md "Stereo rig calibrations"). Every reader throws InputError
// naming the file, line and key on a missing or malformed value; none checks the geometry
// (CheckStereoRig does).
#include <string>

#include "system/datasets/stereo_rig.h"

namespace cslam {

/// A pair of EuRoC/ASL `sensor.yaml` files (T_BS, resolution, intrinsics [fu fv cu cv],
/// distortion_model, distortion_coefficients). cam1_from_cam0 = T_BS(cam1)⁻¹ · T_BS(cam0).
StereoRig ReadEurocSensorPair(const std::string& cam0_yaml, const std::string& cam1_yaml);

/// A Kalibr `camchain.yaml`: cam0 and cam1 with camera_model pinhole, intrinsics,
/// distortion_model, distortion_coeffs, resolution; cam1's T_cn_cnm1 is cam1_from_cam0.
StereoRig ReadKalibrCamchain(const std::string& path);

/// OpenCV stereo calibration output: M1 D1 M2 D2 R T (x1 = R·x0 + T), image_width and
/// image_height, a required `unit` of T (m, cm or mm; converted to metres), an optional
/// `distortion_model` (radtan by default, `fisheye`/`equidistant` for cv::fisheye), and
/// R1 R2 P1 P2 used as the rectification when all four are present.
StereoRig ReadOpenCvStereoCalibration(const std::string& path);

/// An ORB-SLAM3 stereo settings file (File.version "1.0"): Camera.type PinHole or
/// KannalaBrandt8, Camera1.* / Camera2.* intrinsics and coefficients, Camera.width/height,
/// Stereo.T_c1_c2 (cam0_from_cam1).
StereoRig ReadOrbSlam3Settings(const std::string& path);

/// Any one-file calibration above, recognised by its keys (cam0+cam1 → Kalibr, M1 → OpenCV,
/// Camera1.fx → ORB-SLAM3). A single EuRoC sensor.yaml is refused with a hint.
StereoRig ReadRigCalibration(const std::string& path);

/// `rig` in Kalibr camchain.yaml form (rig.yaml of a run: the calibration as it was read).
std::string KalibrCamchainText(const StereoRig& rig);

}  // namespace cslam
