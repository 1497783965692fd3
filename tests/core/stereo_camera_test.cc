#include "core/stereo_camera.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

StereoCamera KittiLike() {
  StereoCamera cam;
  cam.fx = 721.5377;
  cam.fy = 718.0;  // deliberately != fx so the fx/fy ratio is exercised
  cam.cx = 609.5593;
  cam.cy = 172.854;
  cam.baseline = 0.537;
  cam.width = 1242;
  cam.height = 375;
  return cam;
}

TEST(StereoCamera, ProjectThenBackProjectRoundTripsOverAGrid) {
  const StereoCamera cam = KittiLike();
  for (double x = -8; x <= 8; x += 2)
    for (double y = -2; y <= 2; y += 1)
      for (double z = 2; z <= 60; z += 7) {
        const Eigen::Vector3d p(x, y, z);
        Eigen::Vector3d uv, q;
        ASSERT_TRUE(cam.Project(p, &uv));
        EXPECT_NEAR(uv(0) - uv(2), cam.fx * cam.baseline / z, 1e-9);
        ASSERT_TRUE(cam.BackProject(uv, &q));
        EXPECT_TRUE(testing::MatrixNear(p, q, 1e-9 * z));
      }
}

TEST(StereoCamera, RejectsPointsBehindAndNonPositiveDisparity) {
  const StereoCamera cam = KittiLike();
  Eigen::Vector3d uv, p;
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0, 0, -1), &uv));
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0, 0, 0), &uv));
  EXPECT_FALSE(cam.BackProject(Eigen::Vector3d(100, 50, 100), &p));
  EXPECT_FALSE(cam.BackProject(Eigen::Vector3d(100, 50, 101), &p));
}

TEST(StereoCamera, BackProjectionJacobianMatchesNumericDifferentiation) {
  const StereoCamera cam = KittiLike();
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(700, 200, 650), Eigen::Vector3d(100, 20, 92.5),
                                  Eigen::Vector3d(1200, 370, 1100)}) {
    Eigen::Vector3d p;
    Eigen::Matrix3d J;
    ASSERT_TRUE(cam.BackProject<double>(x, &p, &J));
    Eigen::Matrix3d Jn;
    const double h = 1e-5;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d xp = x, xm = x, pp, pm;
      xp(k) += h;
      xm(k) -= h;
      ASSERT_TRUE(cam.BackProject(xp, &pp));
      ASSERT_TRUE(cam.BackProject(xm, &pm));
      Jn.col(k) = (pp - pm) / (2 * h);
    }
    EXPECT_TRUE(testing::MatrixNear(J, Jn, 1e-6 * std::max(1.0, Jn.cwiseAbs().maxCoeff())));
  }
}

TEST(StereoCamera, JacobianRowsFollowTheSpecFormula) {
  // clusterslam_spec.md §1 writes the rows out; check a single point against it literally.
  const StereoCamera cam = KittiLike();
  const double uL = 700, vL = 200, uR = 650, d = uL - uR, b = cam.baseline;
  Eigen::Vector3d p;
  Eigen::Matrix3d J;
  ASSERT_TRUE(cam.BackProject<double>(Eigen::Vector3d(uL, vL, uR), &p, &J));
  Eigen::Matrix3d spec;
  spec << b * (cam.cx - uR) / (d * d), 0, b * (uL - cam.cx) / (d * d),
      -(vL - cam.cy) * cam.fx * b / (cam.fy * d * d), cam.fx * b / (cam.fy * d),
      (vL - cam.cy) * cam.fx * b / (cam.fy * d * d), -cam.fx * b / (d * d), 0, cam.fx * b / (d * d);
  EXPECT_TRUE(testing::MatrixNear(J, spec, 1e-12));
}

TEST(StereoCamera, PointCovarianceGrowsWithDepthSquaredInZ) {
  const StereoCamera cam = KittiLike();
  const Eigen::Matrix3d pix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d near_x, far_x;
  cam.Project(Eigen::Vector3d(0, 0, 5), &near_x);
  cam.Project(Eigen::Vector3d(0, 0, 20), &far_x);
  const double ratio = cam.PointCovariance(far_x, pix)(2, 2) / cam.PointCovariance(near_x, pix)(2, 2);
  EXPECT_NEAR(ratio, 256.0, 1e-6);  // σ_Z ∝ Z², so variance ∝ Z⁴: (20/5)^4
}

TEST(StereoCamera, CheckNamesTheBadField) {
  StereoCamera cam = KittiLike();
  cam.baseline = 0;
  try {
    cam.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("baseline"), std::string::npos);
  }
  cam = KittiLike();
  cam.fx = -1;
  EXPECT_THROW(cam.Check(), ConfigError);
  EXPECT_NO_THROW(KittiLike().Check());
}

}  // namespace
}  // namespace cslam
