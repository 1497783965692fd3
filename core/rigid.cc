#include "core/rigid.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace cslam {

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) {
    Eigen::Matrix3d W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return Eigen::Matrix3d::Identity() + W;
  }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

double RotationAngle(const Eigen::Matrix3d& R) {
  // atan2 of (|skew part|, trace part) stays accurate at both ends, unlike acos.
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
}

Pose PoseFromVector(const Vector6d& xi) {
  Pose pose = Pose::Identity();
  pose.linear() = ExpSO3(xi.head<3>());
  pose.translation() = xi.tail<3>();
  return pose;
}

Vector6d PoseToVector(const Pose& pose) {
  Vector6d xi;
  xi.head<3>() = LogSO3(pose.linear());
  xi.tail<3>() = pose.translation();
  return xi;
}

Sim3 AlignUmeyama(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst,
                  bool with_scale) {
  CSLAM_CHECK(src.size() == dst.size(), "AlignUmeyama needs corresponding point lists");
  Sim3 out;
  const size_t n = src.size();
  if (n == 0) return out;
  Eigen::Vector3d mu_s = Eigen::Vector3d::Zero(), mu_d = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mu_s += src[i];
    mu_d += dst[i];
  }
  mu_s /= double(n);
  mu_d /= double(n);
  if (n < 3) {
    out.rigid.translation() = mu_d - mu_s;
    return out;
  }
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var_s = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = src[i] - mu_s, b = dst[i] - mu_d;
    cov += b * a.transpose();
    var_s += a.squaredNorm();
  }
  cov /= double(n);
  var_s /= double(n);
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  double scale = 1.0;
  if (with_scale && var_s > 0) scale = (svd.singularValues().asDiagonal() * S).trace() / var_s;
  out.scale = scale;
  out.rigid.linear() = R;
  out.rigid.translation() = mu_d - scale * R * mu_s;
  return out;
}

Pose Interpolate(const Pose& a, const Pose& b, double t) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Pose out = Pose::Identity();
  out.linear() = qa.slerp(t, qb).toRotationMatrix();
  out.translation() = (1 - t) * a.translation() + t * b.translation();
  return out;
}

}  // namespace cslam
