#include "system/oxts.h"

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

}  // namespace
}  // namespace cslam
