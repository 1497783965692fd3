#include "system/map/motion_agreement.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/matchers.h"

namespace cslam {
namespace {

Pose MakePose(double yaw, double x, double y, double z) {
  Vector6d xi;
  xi << 0, yaw, 0, x, y, z;
  return PoseFromVector(xi);
}

// A body driving ahead of a camera that follows it, 20 m away.
std::map<int, Pose> Body(int begin, int end, double speed) {
  std::map<int, Pose> t;
  for (int f = begin; f < end; ++f) t[f] = MakePose(0.02 * f, 0.1 * f, 0, 20 + speed * f);
  return t;
}

std::vector<std::optional<Pose>> Camera(int frames) {
  std::vector<std::optional<Pose>> cam;
  for (int f = 0; f < frames; ++f) cam.push_back(MakePose(0, 0, 0, 1.0 * f));
  return cam;
}

const std::vector<Eigen::Vector3d> kPoints = {{1, 0, 0}, {-1, 0.5, 2}, {0, -0.5, -2}, {0.5, 0, 1}};

TEST(MotionAgreement, TheSameBodyInTwoFramesAgreesAndRecoversTheOffset) {
  const std::map<int, Pose> a = Body(0, 30, 1.0);
  const Pose a_from_b = MakePose(0.4, 1, -2, 0.5);
  std::map<int, Pose> b;
  for (const auto& [f, pose] : Body(10, 40, 1.0)) b[f] = pose * a_from_b;
  const MotionAgreement m = CompareMotions(a, b, kPoints, Camera(40));
  EXPECT_EQ(m.frames, 20);
  EXPECT_LT(m.rms_m, 1e-9);
  EXPECT_TRUE(testing::PoseNear(m.a_from_b, a_from_b, 1e-9, 1e-9));
  EXPECT_GT(m.mean_range_m, 15);
  EXPECT_LT(m.relative_rms(), 1e-9);
}

TEST(MotionAgreement, ABodyDriftingAwayDisagreesByItsDrift) {
  // b gains 0.1 m per frame on a: over 20 frames the best constant offset is off by about
  // the RMS of a ramp from -1 to 1 m (1/sqrt(3) = 0.58 m).
  const MotionAgreement m = CompareMotions(Body(0, 20, 1.0), Body(0, 20, 1.1), kPoints, Camera(20));
  EXPECT_EQ(m.frames, 20);
  EXPECT_GT(m.rms_m, 0.5);
  EXPECT_LT(m.rms_m, 0.65);
}

TEST(MotionAgreement, AStaticTrajectoryAgreesWithABodyThatHoldsStill) {
  std::map<int, Pose> b;
  for (int f = 0; f < 10; ++f) b[f] = MakePose(0.3, 5, 0, 30);
  const MotionAgreement still = CompareMotions(StaticTrajectory(b), b, kPoints, Camera(10));
  EXPECT_EQ(still.frames, 10);
  EXPECT_LT(still.rms_m, 1e-9);
  const MotionAgreement moving = CompareMotions(StaticTrajectory(b), Body(0, 10, 1.0), kPoints, Camera(10));
  EXPECT_GT(moving.rms_m, 1.0);
}

TEST(MotionAgreement, FittingOnEvenlySpreadFramesCountsThemAllAndFindsTheSameAnswer) {
  const Pose a_from_b = MakePose(0.4, 1, -2, 0.5);
  std::map<int, Pose> b;
  for (const auto& [f, pose] : Body(0, 200, 1.0)) b[f] = pose * a_from_b;
  const MotionAgreement capped = CompareMotions(Body(0, 200, 1.0), b, kPoints, Camera(200), 5, 30);
  EXPECT_EQ(capped.frames, 200);
  EXPECT_LT(capped.rms_m, 1e-9);
  EXPECT_TRUE(testing::PoseNear(capped.a_from_b, a_from_b, 1e-9, 1e-9));
  // A drift is measured on the spread frames about as on all of them (a ramp's RMS).
  const MotionAgreement all = CompareMotions(Body(0, 200, 1.0), Body(0, 200, 1.01), kPoints, Camera(200));
  const MotionAgreement spread =
      CompareMotions(Body(0, 200, 1.0), Body(0, 200, 1.01), kPoints, Camera(200), 5, 30);
  EXPECT_GT(all.rms_m, 0.5);
  EXPECT_NEAR(spread.rms_m, all.rms_m, 0.05 * all.rms_m);
  EXPECT_NEAR(spread.mean_range_m, all.mean_range_m, 0.05 * all.mean_range_m);
}

TEST(MotionAgreement, NoSharedFrameMeansNothingToCompare) {
  const MotionAgreement m = CompareMotions(Body(0, 10, 1.0), Body(10, 20, 1.0), kPoints, Camera(20));
  EXPECT_EQ(m.frames, 0);
}

TEST(MotionAgreement, WithoutCameraPosesTheRelativeErrorIsInfinite) {
  const MotionAgreement m = CompareMotions(Body(0, 10, 1.0), Body(0, 10, 1.0), kPoints);
  EXPECT_EQ(m.frames, 10);
  EXPECT_TRUE(std::isinf(m.relative_rms()));
}

TEST(MotionAgreement, ASinglePointStillMeasuresRotation) {
  // Same translation of the point's centre, but b spins about it: one point alone could not
  // show that; the padding points 1 m away do.
  std::map<int, Pose> a, b;
  for (int f = 0; f < 10; ++f) {
    a[f] = MakePose(0, 0, 0, 20);
    b[f] = MakePose(0.1 * f, 0, 0, 20);
  }
  const MotionAgreement m = CompareMotions(a, b, {Eigen::Vector3d::Zero()}, Camera(10));
  EXPECT_GT(m.rms_m, 0.2);
}

}  // namespace
}  // namespace cslam
