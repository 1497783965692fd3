#pragma once
// KITTI raw OXTS (GPS/IMU) packets and their conversion to camera ground-truth poses
// (formats.md, "OXTS → ground-truth poses"; the KITTI devkit's convertOxtsToPose).
#include <string>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// The fields of one OXTS packet this project uses (the file has 30; all are validated).
struct OxtsPacket {
  double lat = 0, lon = 0;  ///< degrees
  double alt = 0;           ///< metres
  double roll = 0, pitch = 0, yaw = 0;  ///< radians; yaw 0 = east, counter-clockwise
  double vf = 0, vl = 0, vu = 0;  ///< velocity in the IMU frame (forward, left, up), m/s
  double pos_accuracy = 0;  ///< metres
};

/// Reads `dir`/data/*.txt in name order. Throws InputError naming the file (and line 1) when
/// the folder is missing or empty or a packet does not hold 30 finite numbers.
std::vector<OxtsPacket> ReadOxts(const std::string& dir);

/// world_from_cam per packet with world = the camera at packet 0: T·imu0_from_imu(k)·T⁻¹ with
/// T = cam_from_imu; the Mercator scale is taken from the first packet.
std::vector<Pose> OxtsToCameraPoses(const std::vector<OxtsPacket>& packets, const Pose& cam_from_imu);

/// Camera positions from the packets' own velocities instead of their GPS positions: (vf, vl,
/// vu) rotated by roll/pitch/yaw and integrated by the trapezoid rule over `timestamps` (one per
/// packet, seconds), in OxtsToCameraPoses' frame. One device's two estimates of one path: how
/// far they disagree is a floor under any error measured against the GPS ground truth.
std::vector<Eigen::Vector3d> OxtsDeadReckonedCameraPositions(const std::vector<OxtsPacket>& packets,
                                                             const std::vector<double>& timestamps,
                                                             const Pose& cam_from_imu);

}  // namespace cslam
