#include "system/map/observed_position.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "tests/support/cameras.h"
#include "tests/system/map/car_points.h"

namespace cslam {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kPixelSigma = 0.25;

Pose BodyAt(double x, double z, double yaw_deg) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, 1.0, z);
  return p;
}

// The keypoints of `in_body` (only those on the camera's side of the body: a car shows its
// back) with the body at `world_from_body`, the camera at the world's origin, noise of
// kPixelSigma; `shape_scale` scales the places the caller knows, not the true ones.
std::vector<BodyKeypoint> Keypoints(const std::vector<Eigen::Vector3d>& in_body,
                                    const Pose& world_from_body, unsigned seed,
                                    double shape_scale = 1.0) {
  const StereoCamera camera = testing::KittiSizedCamera();
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, kPixelSigma);
  std::vector<BodyKeypoint> out;
  for (const Eigen::Vector3d& b : in_body) {
    if (b.z() > 0) continue;  // the far half is hidden
    Eigen::Vector3d x;
    if (!camera.Project(Eigen::Vector3d(world_from_body * b), &x)) continue;
    const double d = x(0) - x(2);
    x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    if (!(x(0) - x(2) > 0) || d <= 0) continue;
    out.push_back({shape_scale * b, x, kPixelSigma * kPixelSigma * Eigen::Matrix3d::Identity()});
  }
  return out;
}

TEST(ObserveBodyPose, AFarCarsPlaceAndHeadingComeFromItsKeypointsStartedHalfATurnAway) {
  const std::vector<Eigen::Vector3d> car = testing::CarPoints(3);
  const Pose truth = BodyAt(-3, 30, 20);
  const std::vector<BodyKeypoint> keypoints = Keypoints(car, truth, 1);
  ASSERT_GE(keypoints.size(), 15u);
  // The windows' axes are flipped: half a turn plus 10° from the truth.
  const Eigen::Matrix3d flipped =
      Eigen::AngleAxisd(190 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix() * truth.linear();
  const auto pose = ObserveBodyPose(keypoints, {flipped, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()) * flipped},
                                    Pose::Identity(), testing::KittiSizedCamera());
  ASSERT_TRUE(pose.has_value());
  // Visible points sit a metre in front of the origin: a heading left flipped would put the
  // body 2 m off in depth, where the disparities know it to about 0.2 m (1 σ).
  const Eigen::Vector3d error = pose->world_from_body.translation() - truth.translation();
  EXPECT_LT(error.norm(), 0.6);
  EXPECT_LT(error.dot(pose->position_cov.ldlt().solve(error)), 16.27);
  EXPECT_LT(RotationAngle(pose->world_from_body.linear() * truth.linear().transpose()), 10 * kDeg);
  EXPECT_GE(pose->inliers, static_cast<int>(keypoints.size()) - 2);
  // Its covariance says what it knows: metres in depth are not claimed to the centimetre.
  EXPECT_GT(pose->position_cov(2, 2), pose->position_cov(0, 0));
}

TEST(ObserveBodyPose, AShapeTenPercentSmallStillGetsItsDepthFromTheDisparities) {
  const std::vector<Eigen::Vector3d> car = testing::CarPoints(5);
  const Pose truth = BodyAt(2, 30, -10);
  // Scaled about the origin, the places know the body as 10 % smaller than it is; fitted at
  // that size, its apparent width would put it 3 m nearer.
  const std::vector<BodyKeypoint> keypoints = Keypoints(car, truth, 2, 0.9);
  const auto pose = ObserveBodyPose(keypoints, {truth.linear()}, Pose::Identity(), testing::KittiSizedCamera());
  ASSERT_TRUE(pose.has_value());
  EXPECT_NEAR(pose->scale, 1 / 0.9, 0.05);
  EXPECT_LT((pose->world_from_body.translation() - truth.translation()).norm(), 0.6);
}

TEST(ObserveBodyPose, PointsOfAnotherBodyTheClusterTookInDoNotPullIt) {
  std::vector<Eigen::Vector3d> car = testing::CarPoints(7);
  const Pose truth = BodyAt(-2, 25, 5);
  std::vector<BodyKeypoint> keypoints = Keypoints(car, truth, 3);
  const size_t own = keypoints.size();
  // A third as many keypoints again from a car 3 m to its left, 2 m further.
  std::vector<BodyKeypoint> other = Keypoints(testing::CarPoints(8), BodyAt(-5, 27, 5), 4);
  other.resize(own / 3);
  for (size_t i = 0; i < other.size(); ++i) other[i].in_body = car[i];  // labelled as this car's
  keypoints.insert(keypoints.end(), other.begin(), other.end());
  const auto pose = ObserveBodyPose(keypoints, {truth.linear()}, Pose::Identity(), testing::KittiSizedCamera());
  ASSERT_TRUE(pose.has_value());
  EXPECT_LT((pose->world_from_body.translation() - truth.translation()).norm(), 0.3);
  EXPECT_LE(pose->inliers, static_cast<int>(own) + 1);
}

TEST(ObserveBodyPose, TooFewKeypointsOrKeypointsNoBodyExplainsGiveNothing) {
  const std::vector<Eigen::Vector3d> car = testing::CarPoints(3);
  std::vector<BodyKeypoint> keypoints = Keypoints(car, BodyAt(0, 20, 0), 5);
  std::vector<BodyKeypoint> few(keypoints.begin(), keypoints.begin() + 5);
  EXPECT_FALSE(ObserveBodyPose(few, {Eigen::Matrix3d::Identity()}, Pose::Identity(),
                               testing::KittiSizedCamera()).has_value());
  // Shuffled places: no rigid body makes these keypoints.
  std::mt19937 rng(9);
  std::vector<BodyKeypoint> shuffled = keypoints;
  for (BodyKeypoint& k : shuffled) k.in_body = 3 * car[std::uniform_int_distribution<size_t>(0, car.size() - 1)(rng)];
  const auto pose = ObserveBodyPose(shuffled, {Eigen::Matrix3d::Identity()}, Pose::Identity(),
                                    testing::KittiSizedCamera(), static_cast<int>(shuffled.size()) / 2);
  EXPECT_FALSE(pose.has_value());
}

}  // namespace
}  // namespace cslam
