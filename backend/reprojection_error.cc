#include "backend/reprojection_error.h"

namespace cslam {

namespace {
Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}
}  // namespace

bool StereoReprojectionWithJacobians(const StereoCamera& camera, const Eigen::Vector3d& x,
                                     const Eigen::Matrix3d& sqrt_info, const double* q,
                                     const double* t, const double* point, double* residual,
                                     double* d_q, double* d_t, double* d_point) {
  const Eigen::Map<const Eigen::Quaterniond> rotation(q);
  const Eigen::Map<const Eigen::Vector3d> translation(t);
  const Eigen::Map<const Eigen::Vector3d> p(point);
  // The same expression as the template (Eigen's q * p): the residuals agree to rounding.
  const Eigen::Vector3d p_in_cam = rotation * p + translation;
  if (!WhitenedStereoResidual<double>(camera, x, sqrt_info, p_in_cam, residual)) return false;
  if (!d_q && !d_t && !d_point) return true;

  // dr/dp_in_cam = −S dπ/dp_in_cam.
  const double inv_z = 1.0 / p_in_cam.z();
  const double u = p_in_cam.x() * inv_z, v = p_in_cam.y() * inv_z;
  Eigen::Matrix3d d_projection;
  d_projection << camera.fx * inv_z, 0.0, -camera.fx * u * inv_z,  //
      0.0, camera.fy * inv_z, -camera.fy * v * inv_z,              //
      camera.fx * inv_z, 0.0, -camera.fx * (u - camera.baseline * inv_z) * inv_z;
  const Eigen::Matrix3d d_cam = -sqrt_info * d_projection;

  // Eigen's q * p = p + 2w (v×p) + 2 v×(v×p), differentiated as written (q not normalised).
  const Eigen::Vector3d vec = rotation.vec();
  const double w = rotation.w();
  using RowMajor33 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  if (d_t) {
    Eigen::Map<RowMajor33> out(d_t);
    out = d_cam;
  }
  if (d_point) {
    const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() + 2.0 * w * Skew(vec) +
                              2.0 * (vec * vec.transpose() -
                                     vec.squaredNorm() * Eigen::Matrix3d::Identity());
    Eigen::Map<RowMajor33> out(d_point);
    out = d_cam * m;
  }
  if (d_q) {
    Eigen::Matrix<double, 3, 4> d_rotated;
    d_rotated.leftCols<3>() = -2.0 * w * Skew(p) +
                              2.0 * (vec.dot(p) * Eigen::Matrix3d::Identity() +
                                     vec * p.transpose() - 2.0 * p * vec.transpose());
    d_rotated.col(3) = 2.0 * vec.cross(p);
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out(d_q);
    out = d_cam * d_rotated;
  }
  return true;
}

}  // namespace cslam
