#include "system/datasets/oxts.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

constexpr int kOxtsFields = 30;
constexpr double kEarthRadius = 6378137.0;  // metres, as in the KITTI devkit

OxtsPacket ReadPacket(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "OXTS packet");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") != std::string::npos) break;
  }
  const std::vector<double> v = ParseNumbers(line, path, std::max(line_no, 1));
  if (static_cast<int>(v.size()) != kOxtsFields)
    throw InputError(path, std::max(line_no, 1),
                     "expected " + std::to_string(kOxtsFields) + " numbers (see dataformat.txt), got " +
                         std::to_string(v.size()));
  if (std::abs(v[0]) > 90 || std::abs(v[1]) > 180)
    throw InputError(path, line_no, "expected latitude in [-90, 90] and longitude in [-180, 180]");
  OxtsPacket p;
  p.lat = v[0];
  p.lon = v[1];
  p.alt = v[2];
  p.roll = v[3];
  p.pitch = v[4];
  p.yaw = v[5];
  p.vf = v[8];
  p.vl = v[9];
  p.vu = v[10];
  p.pos_accuracy = v[23];
  return p;
}

// KITTI devkit convention: yaw about z (up), then pitch about y, then roll about x.
Eigen::Matrix3d WorldFromImuRotation(const OxtsPacket& p) {
  return (Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p.pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(p.roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

std::vector<OxtsPacket> ReadOxts(const std::string& dir) {
  const fs::path data = fs::path(dir) / "data";
  std::error_code ec;
  if (!fs::is_directory(data, ec))
    throw InputError(data.string(), "expected the OXTS packet folder; it is missing");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(data, ec))
    if (entry.path().extension() == ".txt") files.push_back(entry.path().string());
  if (files.empty()) throw InputError(data.string(), "expected OXTS packets *.txt; none found");
  std::sort(files.begin(), files.end());
  std::vector<OxtsPacket> packets;
  packets.reserve(files.size());
  for (const std::string& f : files) packets.push_back(ReadPacket(f));
  return packets;
}

std::vector<Pose> OxtsToCameraPoses(const std::vector<OxtsPacket>& packets, const Pose& cam_from_imu) {
  std::vector<Pose> poses;
  if (packets.empty()) return poses;
  const double scale = std::cos(packets[0].lat * M_PI / 180.0);
  Pose imu0_from_world = Pose::Identity();
  const Pose imu_from_cam = cam_from_imu.inverse();
  poses.reserve(packets.size());
  for (size_t k = 0; k < packets.size(); ++k) {
    const OxtsPacket& p = packets[k];
    Pose world_from_imu = Pose::Identity();
    world_from_imu.translation() =
        Eigen::Vector3d(scale * kEarthRadius * p.lon * M_PI / 180.0,
                        scale * kEarthRadius * std::log(std::tan((90.0 + p.lat) * M_PI / 360.0)),
                        p.alt);
    world_from_imu.linear() = WorldFromImuRotation(p);
    if (k == 0) imu0_from_world = world_from_imu.inverse();
    poses.push_back(cam_from_imu * (imu0_from_world * world_from_imu) * imu_from_cam);
  }
  return poses;
}

std::vector<Eigen::Vector3d> OxtsDeadReckonedCameraPositions(const std::vector<OxtsPacket>& packets,
                                                             const std::vector<double>& timestamps,
                                                             const Pose& cam_from_imu) {
  std::vector<Eigen::Vector3d> positions;
  if (packets.empty()) return positions;
  if (timestamps.size() != packets.size())
    throw std::invalid_argument("OxtsDeadReckonedCameraPositions: one timestamp per packet");
  // World = the IMU at packet 0, its axes east/north/up like the Mercator frame's.
  Pose imu0_from_world = Pose::Identity();
  imu0_from_world.linear() = WorldFromImuRotation(packets[0]).transpose();
  const Pose imu_from_cam = cam_from_imu.inverse();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_before = Eigen::Vector3d::Zero();
  positions.reserve(packets.size());
  for (size_t k = 0; k < packets.size(); ++k) {
    const OxtsPacket& p = packets[k];
    const Eigen::Matrix3d rotation = WorldFromImuRotation(p);
    const Eigen::Vector3d velocity = rotation * Eigen::Vector3d(p.vf, p.vl, p.vu);
    if (k > 0) position += 0.5 * (velocity + velocity_before) * (timestamps[k] - timestamps[k - 1]);
    velocity_before = velocity;
    Pose world_from_imu = Pose::Identity();
    world_from_imu.linear() = rotation;
    world_from_imu.translation() = position;
    positions.push_back((cam_from_imu * (imu0_from_world * world_from_imu) * imu_from_cam).translation());
  }
  return positions;
}

}  // namespace cslam
