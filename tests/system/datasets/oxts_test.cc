#include "system/datasets/oxts.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/matchers.h"

namespace cslam {
namespace {

// The KITTI mounting: IMU x forward, y left, z up; camera x right, y down, z forward; the
// IMU 1 m behind and 0.7 m below the camera.
Pose CamFromImu() {
  Pose cam_from_imu = Pose::Identity();
  cam_from_imu.linear() << 0, -1, 0,  //
      0, 0, -1,                      //
      1, 0, 0;
  cam_from_imu.translation() = Eigen::Vector3d(0.0, 0.7, -1.0);
  return cam_from_imu;
}

OxtsPacket Packet(double lat, double lon, double yaw) {
  OxtsPacket p;
  p.lat = lat;
  p.lon = lon;
  p.alt = 100.0;
  p.yaw = yaw;
  return p;
}

TEST(Oxts, DrivingEastWithYawZeroMovesTheCameraForward) {
  const double lat = 49.0, lon = 8.4;
  // 10 m east at this latitude on the Mercator projection scaled by cos(lat0).
  const double dlon = 10.0 / (std::cos(lat * M_PI / 180.0) * 6378137.0 * M_PI / 180.0);
  const std::vector<Pose> poses =
      OxtsToCameraPoses({Packet(lat, lon, 0.0), Packet(lat, lon + dlon, 0.0)}, CamFromImu());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(testing::PoseNear(poses[0], Pose::Identity(), 1e-12, 1e-9));
  Pose expected = Pose::Identity();
  expected.translation() = Eigen::Vector3d(0, 0, 10.0);
  EXPECT_TRUE(testing::PoseNear(poses[1], expected, 1e-12, 1e-6));
}

TEST(Oxts, TurningLeftInPlaceRotatesAboutTheImuNotTheCamera) {
  // Yaw +90° (counter-clockwise from above): the car now faces north, the camera's old −x.
  const std::vector<Pose> poses =
      OxtsToCameraPoses({Packet(49.0, 8.4, 0.3), Packet(49.0, 8.4, 0.3 + M_PI / 2)}, CamFromImu());
  const Eigen::Vector3d forward = poses[1].linear() * Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(testing::MatrixNear(forward, Eigen::Vector3d(-1, 0, 0), 1e-12));
  // The camera sits 1 m ahead of the IMU: turning about the IMU swings it by (−1, 0, −1).
  EXPECT_TRUE(testing::MatrixNear(poses[1].translation(), Eigen::Vector3d(-1, 0, -1), 1e-9));
}

TEST(Oxts, ClimbingMovesTheCameraUpWhichIsMinusY) {
  OxtsPacket a = Packet(49.0, 8.4, 1.0), b = a;
  b.alt += 2.0;
  const std::vector<Pose> poses = OxtsToCameraPoses({a, b}, CamFromImu());
  EXPECT_TRUE(testing::MatrixNear(poses[1].translation(), Eigen::Vector3d(0, -2, 0), 1e-9));
}

// A car circling counter-clockwise at 8 m/s on a 40 m radius, sampled at 10 Hz, its GPS
// positions exact; `speed_factor` scales the velocities the packets report.
std::vector<OxtsPacket> Circle(int n, double speed_factor) {
  const double lat0 = 49.0, lon0 = 8.4, radius = 40.0, speed = 8.0, dt = 0.1;
  const double scale = std::cos(lat0 * M_PI / 180.0), r_earth = 6378137.0;
  const double my0 = scale * r_earth * std::log(std::tan((90.0 + lat0) * M_PI / 360.0));
  std::vector<OxtsPacket> packets;
  for (int k = 0; k < n; ++k) {
    const double angle = speed * dt * k / radius;  // heading = angle (yaw 0 = east at k = 0)
    const double east = radius * std::sin(angle), north = radius * (1 - std::cos(angle));
    OxtsPacket p = Packet(0, lon0 + east / (scale * r_earth) * 180.0 / M_PI, angle);
    p.lat = 360.0 / M_PI * std::atan(std::exp((my0 + north) / (scale * r_earth))) - 90.0;
    p.vf = speed * speed_factor;
    packets.push_back(p);
  }
  return packets;
}

TEST(Oxts, IntegratedVelocitiesRetraceConsistentGpsPositions) {
  const std::vector<OxtsPacket> packets = Circle(100, 1.0);
  std::vector<double> times;
  for (int k = 0; k < 100; ++k) times.push_back(0.1 * k);
  const std::vector<Pose> gps = OxtsToCameraPoses(packets, CamFromImu());
  const std::vector<Eigen::Vector3d> integrated =
      OxtsDeadReckonedCameraPositions(packets, times, CamFromImu());
  ASSERT_EQ(integrated.size(), gps.size());
  // 80 m of a 40 m circle: the trapezoid rule's chord error stays at millimetres.
  for (size_t k = 0; k < gps.size(); ++k)
    EXPECT_TRUE(testing::MatrixNear(integrated[k], gps[k].translation(), 5e-3)) << "packet " << k;
  EXPECT_GT(gps.back().translation().norm(), 40.0);
}

TEST(Oxts, IntegratedVelocitiesFollowTheSpeedTheDeviceReports) {
  // A speed sensor 5 % fast: the integrated path is 5 % longer than the GPS one.
  const std::vector<OxtsPacket> packets = Circle(50, 1.05);
  std::vector<double> times;
  for (int k = 0; k < 50; ++k) times.push_back(0.1 * k);
  const std::vector<Eigen::Vector3d> integrated =
      OxtsDeadReckonedCameraPositions(packets, times, CamFromImu());
  const std::vector<Pose> gps = OxtsToCameraPoses(packets, CamFromImu());
  double length_integrated = 0, length_gps = 0;
  for (size_t k = 1; k < integrated.size(); ++k) {
    length_integrated += (integrated[k] - integrated[k - 1]).norm();
    length_gps += (gps[k].translation() - gps[k - 1].translation()).norm();
  }
  EXPECT_NEAR(length_integrated / length_gps, 1.05, 1e-3);
}

}  // namespace
}  // namespace cslam
