#include "system/eval/object_motion_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rigid.h"

namespace cslam {
namespace {

constexpr double kDeg = M_PI / 180.0;

Pose At(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = ExpSO3(rotation_vector);
  p.translation() = t;
  return p;
}

// A car ahead of a camera that drives and turns behind it (y down, z forward): the car drives
// along z at 10 m/s (1 m per frame), turning 1° per frame; the camera follows at 2 m/s.
std::vector<ObjectFramePoses> CarAhead(int n) {
  std::vector<ObjectFramePoses> frames;
  for (int k = 0; k < n; ++k) {
    ObjectFramePoses f;
    f.frame = k;
    f.gt_world_from_object = At(Eigen::Vector3d(0, k * kDeg, 0), Eigen::Vector3d(0.05 * k * k, 0.5, 30 + k));
    f.gt_world_from_cam = At(Eigen::Vector3d(0, 0.3 * k * kDeg, 0), Eigen::Vector3d(0, 0, 0.2 * k));
    f.est_world_from_object = f.gt_world_from_object;
    f.est_world_from_cam = f.gt_world_from_cam;
    frames.push_back(f);
  }
  return frames;
}

TEST(ObjectMotionError, IsZeroWhateverTheEstimatesWorldAndBodyFrame) {
  // The estimate lives in another world (turned 90°, 100 m away) and puts its body frame 2 m
  // behind and turned against the true one: the motions still agree exactly.
  const Pose world = At(Eigen::Vector3d(0, 0.5 * M_PI, 0.1), Eigen::Vector3d(100, -3, 40));
  const Pose body = At(Eigen::Vector3d(0.2, -0.4, 0), Eigen::Vector3d(0, 0, -2));
  std::vector<ObjectFramePoses> frames = CarAhead(10);
  for (ObjectFramePoses& f : frames) {
    f.est_world_from_object = world * f.gt_world_from_object * body;
    f.est_world_from_cam = world * f.gt_world_from_cam;
  }
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  EXPECT_EQ(e.pairs, 9);
  EXPECT_NEAR(e.me_r_deg, 0, 1e-9);
  EXPECT_NEAR(e.me_t_m, 0, 1e-9);
}

TEST(ObjectMotionError, AHeadingFlippedAboutTheCentreAtOneFrameCostsTwoMotionsItsAngleAndNoTranslation) {
  std::vector<ObjectFramePoses> frames = CarAhead(4);
  // At frame 2 the estimate turns the car by 10° about its own centre (its origin).
  frames[2].est_world_from_object = frames[2].gt_world_from_object * At(Eigen::Vector3d(0, 10 * kDeg, 0), Eigen::Vector3d::Zero());
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  EXPECT_EQ(e.pairs, 3);
  // Motions 1→2 and 2→3 are each 10° off; 0→1 is exact.
  EXPECT_NEAR(e.me_r_deg, 20.0 / 3.0, 1e-9);
  EXPECT_NEAR(e.max_r_deg, 10.0, 1e-9);
  EXPECT_NEAR(e.me_t_m, 0, 1e-9);
}

TEST(ObjectMotionError, APositionOffsetAtOneFrameCostsTwoMotionsItsLength) {
  std::vector<ObjectFramePoses> frames = CarAhead(4);
  frames[1].est_world_from_object.translation() += Eigen::Vector3d(0.3, 0, 0.4);  // 0.5 m
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  EXPECT_NEAR(e.me_r_deg, 0, 1e-9);
  EXPECT_NEAR(e.me_t_m, 2 * 0.5 / 3, 1e-9);
}

TEST(ObjectMotionError, AWrongTurnRateMisplacesTheCentreByWhatTheTurnAboutAnotherPointDoes) {
  // Independent computation: the estimate turns about the camera's origin instead of the car's
  // centre, 1° too much between frames 0 and 1. The centre, 30 m ahead, is then misplaced by
  // the chord 2·30·sin(0.5°) ≈ 0.52 m.
  std::vector<ObjectFramePoses> frames = CarAhead(2);
  for (ObjectFramePoses& f : frames) f.gt_world_from_cam = f.est_world_from_cam = Pose::Identity();
  const Pose extra = At(Eigen::Vector3d(0, 1 * kDeg, 0), Eigen::Vector3d::Zero());  // about the camera
  frames[1].est_world_from_object = extra * frames[1].gt_world_from_object;
  // The centre at frame 1 moves on a circle about the camera's vertical axis.
  const Eigen::Vector3d c = frames[1].gt_world_from_object.translation();
  const double r = std::hypot(c.x(), c.z());
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  EXPECT_NEAR(e.me_r_deg, 1.0, 1e-9);
  EXPECT_NEAR(e.me_t_m, 2 * r * std::sin(0.5 * kDeg), 1e-9);
}

TEST(ObjectMotionError, OnlyConsecutiveFramesArePairs) {
  std::vector<ObjectFramePoses> frames = CarAhead(6);
  frames.erase(frames.begin() + 3);  // frames 0 1 2 4 5: pairs 0-1, 1-2, 4-5
  frames[3].est_world_from_object.translation().x() += 7;  // frame 4, paired only with 5
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  EXPECT_EQ(e.pairs, 3);
  EXPECT_NEAR(e.me_t_m, 7.0 / 3, 1e-9);
  EXPECT_EQ(ComputeObjectMotionError({}).pairs, 0);
}

TEST(LargestFrameToFrameRotation, FindsAFlipAndItsFrameAndSkipsGaps) {
  std::vector<int> frames;
  std::vector<Pose> poses;
  for (int k = 0; k < 12; ++k) {
    if (k == 8) continue;  // a gap: 7 → 9 turns 60°, but they are not consecutive
    double yaw = 2.0 * k + (k == 5 ? 170.0 : 0.0) + (k >= 9 ? 60.0 : 0.0);
    frames.push_back(k);
    poses.push_back(At(Eigen::Vector3d(0, yaw * kDeg, 0), Eigen::Vector3d(k, 0, 30)));
  }
  const auto r = LargestFrameToFrameRotation(frames, poses);
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->deg, 172.0, 1e-6);  // 4 → 5: 2° + 170°
  EXPECT_EQ(r->frame, 5);
  EXPECT_FALSE(LargestFrameToFrameRotation({3}, {Pose::Identity()}));
}

}  // namespace
}  // namespace cslam
