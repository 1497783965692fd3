#include "core/rigid.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/matchers.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

TEST(Rigid, ExpAndLogAreInverse) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d w = testing::Draw3([&] { return u(rng); });
    EXPECT_TRUE(testing::MatrixNear(LogSO3(ExpSO3(w)), w, 1e-9));
    EXPECT_NEAR(RotationAngle(ExpSO3(w)), w.norm(), 1e-9);
  }
  EXPECT_NEAR(RotationAngle(Eigen::Matrix3d::Identity()), 0.0, 1e-15);
}

TEST(Rigid, UmeyamaRecoversAKnownRigidTransform) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 3);
  Vector6d xi;
  xi << 0.3, -0.2, 0.9, 4, -2, 1;
  const Pose dst_from_src = PoseFromVector(xi);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 30; ++i) {
    src.push_back(testing::Draw3([&] { return n(rng); }));
    dst.push_back(dst_from_src * src.back());
  }
  const Sim3 t = AlignUmeyama(src, dst, false);
  EXPECT_NEAR(t.scale, 1.0, 1e-12);
  EXPECT_TRUE(testing::PoseNear(t.rigid, dst_from_src, 1e-9, 1e-9));
}

TEST(Rigid, UmeyamaRecoversAKnownSimilarity) {
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0, 3);
  Vector6d xi;
  xi << -1.0, 0.4, 0.1, 0.5, 7, -3;
  const Pose r = PoseFromVector(xi);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 30; ++i) {
    src.push_back(testing::Draw3([&] { return n(rng); }));
    dst.push_back(2.5 * (r.linear() * src.back()) + r.translation());
  }
  const Sim3 t = AlignUmeyama(src, dst, true);
  EXPECT_NEAR(t.scale, 2.5, 1e-9);
  EXPECT_TRUE(testing::PoseNear(t.rigid, r, 1e-9, 1e-8));
  for (size_t i = 0; i < src.size(); ++i)
    EXPECT_TRUE(testing::MatrixNear(t.Apply(src[i]), dst[i], 1e-8));
}

TEST(Rigid, UmeyamaNeverReturnsAReflection) {
  // Planar points mirrored: the best proper rotation, not the mirror, must come back.
  std::vector<Eigen::Vector3d> src = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.emplace_back(p.x(), p.y(), -p.z());
  const Sim3 t = AlignUmeyama(src, dst, false);
  EXPECT_NEAR(t.rigid.linear().determinant(), 1.0, 1e-12);
}

TEST(Rigid, InterpolateHitsEndpointsAndMidpoint) {
  Vector6d xa, xb;
  xa << 0, 0, 0, 0, 0, 0;
  xb << 0, 0, 1.0, 2, 0, 0;
  const Pose a = PoseFromVector(xa), b = PoseFromVector(xb);
  EXPECT_TRUE(testing::PoseNear(Interpolate(a, b, 0), a, 1e-12, 1e-12));
  EXPECT_TRUE(testing::PoseNear(Interpolate(a, b, 1), b, 1e-12, 1e-12));
  const Pose m = Interpolate(a, b, 0.5);
  EXPECT_NEAR(RotationAngle(m.linear()), 0.5, 1e-12);
  EXPECT_NEAR(m.translation().x(), 1.0, 1e-12);
}

}  // namespace
}  // namespace cslam
