#include "backend/motion_prior.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>

namespace cslam {
namespace {

using Block = std::array<double, 7>;

Block ToBlock(const Pose& cam_from_body) {
  const Eigen::Quaterniond q(cam_from_body.linear());
  const Eigen::Vector3d t = cam_from_body.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

Pose Make(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = r;
  p.translation() = t;
  return p;
}

Eigen::Matrix3d Yaw(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

// A body whose centre moves at constant velocity while it turns at a constant rate, seen from
// a camera that moves on its own: world_from_body_i has R_i = Yaw(ω i) R_0 and puts the centre
// c at p_0 + v i.
struct Track {
  Eigen::Vector3d centre{0.4, -0.2, 1.5};
  Pose world_from_body(int i) const {
    const Eigen::Matrix3d r = Yaw(0.03 * i) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Vector3d p = Eigen::Vector3d(2.0, 0.5, 12.0) + i * Eigen::Vector3d(0.8, 0.0, -0.3);
    return Make(r, p - r * centre);
  }
  Pose world_from_cam(int i) const {
    return Make(Yaw(-0.05 * i + 0.01 * i * i), Eigen::Vector3d(0.1 * i * i, 0.02 * i, 1.1 * i));
  }
};

Eigen::Matrix<double, 6, 1> Residual(const MotionPriorTerm& term, const std::array<Block, 3>& b) {
  Eigen::Matrix<double, 6, 1> r;
  MotionPriorResidual(term, b[0].data(), b[1].data(), b[2].data(), r.data());
  return r;
}

TEST(MotionPrior, AConstantVelocityTurningBodyCostsNothingWhateverTheCameraDoes) {
  const Track track;
  MotionPriorTerm term;
  term.centre = track.centre;
  std::array<Block, 3> blocks;
  for (int i = 0; i < 3; ++i) {
    term.world_from_cam[i] = track.world_from_cam(i);
    blocks[i] = ToBlock(track.world_from_cam(i).inverse() * track.world_from_body(i));
  }
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
  term.centre = track.centre;
  term.sigma_m = 0.05;
  term.sigma_rad = 0.01;
  std::array<Block, 3> blocks;
  const Eigen::Vector3d push(0.1, 0.0, 0.0);
  const double turn = 0.02;
  for (int i = 0; i < 3; ++i) {
    Pose world_from_body = track.world_from_body(i);
    if (i == 2) {
      // Turn about the centre (body frame) and push the centre in the world.
      const Eigen::Vector3d p = world_from_body * track.centre + push;
      const Eigen::Matrix3d r = world_from_body.linear() * Yaw(turn);
      world_from_body = Make(r, p - r * track.centre);
    }
    term.world_from_cam[i] = track.world_from_cam(i);
    blocks[i] = ToBlock(track.world_from_cam(i).inverse() * world_from_body);
  }
  const Eigen::Matrix<double, 6, 1> r = Residual(term, blocks);
  EXPECT_NEAR((r.head<3>() - push / term.sigma_m).norm(), 0.0, 1e-9);
  // Log(Exp(a) Exp(b)) = a + b only to first order: the body's own step (0.03 rad, about a
  // tilted axis) and the extra turn differ by at most ½·0.03·0.02 rad = 0.03 σ.
  EXPECT_NEAR((r.tail<3>() - Eigen::Vector3d(0, turn, 0) / term.sigma_rad).norm(), 0.0, 0.03);
}

}  // namespace
}  // namespace cslam
