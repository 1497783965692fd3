#include "backend/motion_prior.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>

#include "tests/backend/synthetic_bodies.h"

namespace cslam {
namespace {

using Block = std::array<double, 7>;
using testing::MakePose;

Block ToBlock(const Pose& cam_from_body) {
  const Eigen::Quaterniond q(cam_from_body.linear());
  const Eigen::Vector3d t = cam_from_body.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

// A body whose centre moves at constant velocity while it turns at a constant rate, seen from
// a camera that moves on its own: world_from_body_i turns by yaw 0.03 i (pitched by 0.2) and
// puts the centre c at p_0 + v i.
struct Track {
  Eigen::Vector3d centre{0.4, -0.2, 1.5};
  Pose world_from_body(int i) const {
    Pose pose = MakePose(0.03 * i, 0.2, Eigen::Vector3d::Zero());
    pose.translation() = CentredAt(pose, Eigen::Vector3d(2.0, 0.5, 12.0) + i * Eigen::Vector3d(0.8, 0.0, -0.3));
    return pose;
  }
  Pose world_from_cam(int i) const {
    return MakePose(-0.05 * i + 0.01 * i * i, 0.0, Eigen::Vector3d(0.1 * i * i, 0.02 * i, 1.1 * i));
  }
  /// The translation that puts the centre at `p` under `pose`'s rotation.
  Eigen::Vector3d CentredAt(const Pose& pose, const Eigen::Vector3d& p) const {
    return p - pose.linear() * centre;
  }
};

// The term for the track's cameras, and the blocks (cam_from_body) of the given body poses.
std::array<Block, 3> SeenByTheCameras(const Track& track, const std::array<Pose, 3>& world_from_body,
                                      MotionPriorTerm* term) {
  term->centre = track.centre;
  std::array<Block, 3> blocks;
  for (int i = 0; i < 3; ++i) {
    term->world_from_cam[i] = track.world_from_cam(i);
    blocks[i] = ToBlock(track.world_from_cam(i).inverse() * world_from_body[i]);
  }
  return blocks;
}

Eigen::Matrix<double, 6, 1> Residual(const MotionPriorTerm& term, const std::array<Block, 3>& b) {
  Eigen::Matrix<double, 6, 1> r;
  MotionPriorResidual(term, b[0].data(), b[1].data(), b[2].data(), r.data());
  return r;
}

TEST(MotionPrior, AConstantVelocityTurningBodyCostsNothingWhateverTheCameraDoes) {
  const Track track;
  MotionPriorTerm term;
  const std::array<Block, 3> blocks = SeenByTheCameras(
      track, {track.world_from_body(0), track.world_from_body(1), track.world_from_body(2)}, &term);
  EXPECT_LT(Residual(term, blocks).norm(), 1e-9);
}

// A term built without camera poses takes the pose blocks as world_from_body (Eigen leaves a
// default-constructed Isometry3d uninitialised, so the term sets them to the identity).
TEST(MotionPrior, ATermWithoutCameraPosesTakesTheBlocksInTheWorldFrame) {
  const Track track;
  MotionPriorTerm term;
  term.centre = track.centre;
  std::array<Block, 3> blocks;
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(term.world_from_cam[i].isApprox(Pose::Identity()));
    blocks[i] = ToBlock(track.world_from_body(i));
  }
  EXPECT_LT(Residual(term, blocks).norm(), 1e-9);
}

// A centre that is 0.1 m off constant velocity in the third frame and a body that turned
// 0.02 rad more give residuals of exactly those over their sigmas.
TEST(MotionPrior, AnAccelerationAndAnExtraTurnShowUpOverTheirSigmas) {
  const Track track;
  MotionPriorTerm term;
  term.sigma_m = 0.05;
  term.sigma_rad = 0.01;
  const Eigen::Vector3d push(0.1, 0.0, 0.0);
  const double turn = 0.02;
  // The third pose turned about the centre (body frame), the centre pushed in the world.
  const Pose third = track.world_from_body(2);
  Pose turned = third * MakePose(turn, 0.0, Eigen::Vector3d::Zero());
  turned.translation() = track.CentredAt(turned, third * track.centre + push);
  const std::array<Block, 3> blocks =
      SeenByTheCameras(track, {track.world_from_body(0), track.world_from_body(1), turned}, &term);
  const Eigen::Matrix<double, 6, 1> r = Residual(term, blocks);
  EXPECT_NEAR((r.head<3>() - push / term.sigma_m).norm(), 0.0, 1e-9);
  // Log(Exp(a) Exp(b)) = a + b only to first order: the body's own step (0.03 rad, about a
  // tilted axis) and the extra turn differ by at most ½·0.03·0.02 rad = 0.03 σ.
  EXPECT_NEAR((r.tail<3>() - Eigen::Vector3d(0, turn, 0) / term.sigma_rad).norm(), 0.0, 0.03);
}

}  // namespace
}  // namespace cslam
