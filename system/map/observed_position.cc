#include "system/map/observed_position.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace cslam {

namespace {

// χ²₃ quantiles: the Cauchy kernel's scale (95 %) and the inlier gate (99.9 %).
constexpr double kCauchyScale = 7.81;
constexpr double kInlierGate = 16.27;
constexpr double kChi2Median = 2.366;

double Median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

using Matrix7d = Eigen::Matrix<double, 7, 7>;
using Vector7d = Eigen::Matrix<double, 7, 1>;

// The body's pose and the scale of its landmarks' places: a window's shape of a body can be
// a few per cent too small or large, and its apparent size would then move the body in depth
// by as much; with the scale free, the depth comes from the disparities.
struct ScaledPose {
  Pose pose = Pose::Identity();
  double scale = 1;
};

class PoseProblem {
 public:
  PoseProblem(const std::vector<BodyKeypoint>& keypoints, const Pose& world_from_cam,
              const StereoCamera& camera)
      : keypoints_(keypoints), cam_from_world_(world_from_cam.inverse()), camera_(camera) {
    information_.reserve(keypoints.size());
    for (const BodyKeypoint& k : keypoints)
      information_.push_back(k.cov.ldlt().solve(Eigen::Matrix3d::Identity()));
  }

  // Squared whitened residual of keypoint i; with J, its Jacobian (3×6: left rotation, position).
  bool Residual(size_t i, const ScaledPose& body, Eigen::Vector3d* r, Eigen::Matrix<double, 3, 7>* J) const {
    const Eigen::Vector3d q = body.scale * (body.pose.linear() * keypoints_[i].in_body);
    const Eigen::Vector3d p = cam_from_world_ * (body.pose.translation() + q);
    Eigen::Vector3d x;
    if (!camera_.Project(p, &x)) return false;
    *r = keypoints_[i].x - x;
    if (J) {
      const double iz = 1.0 / p.z(), iz2 = iz * iz;
      Eigen::Matrix3d dx_dp;
      dx_dp << camera_.fx * iz, 0, -camera_.fx * p.x() * iz2,  //
          0, camera_.fy * iz, -camera_.fy * p.y() * iz2,        //
          camera_.fx * iz, 0, -camera_.fx * (p.x() - camera_.baseline) * iz2;
      const Eigen::Matrix3d d = -dx_dp * cam_from_world_.linear();
      J->leftCols<3>() = -d * Skew(q);
      J->middleCols<3>(3) = d;
      J->col(6) = d * q;
    }
    return true;
  }

  // Robust (Cauchy) cost; a keypoint that falls behind the camera costs like a far outlier.
  double Cost(const ScaledPose& body) const {
    double cost = 0;
    for (size_t i = 0; i < keypoints_.size(); ++i) {
      Eigen::Vector3d r;
      const double s = Residual(i, body, &r, nullptr) ? r.dot(information_[i] * r) : 1e6;
      cost += std::log1p(s / kCauchyScale);
    }
    return cost;
  }

  // The keypoints within the gate, and the covariance of the position their information
  // gives (the rotation and the scale unknown as well).
  int Inliers(const ScaledPose& body, Eigen::Matrix3d* position_cov) const {
    int n = 0;
    Matrix7d information = Matrix7d::Zero();
    std::vector<double> squared;
    for (size_t i = 0; i < keypoints_.size(); ++i) {
      Eigen::Vector3d r;
      Eigen::Matrix<double, 3, 7> J;
      if (!Residual(i, body, &r, &J)) continue;
      const double s = r.dot(information_[i] * r);
      squared.push_back(s);
      if (!(s < kInlierGate)) continue;
      information += J.transpose() * information_[i] * J;
      ++n;
    }
    information += 1e-9 * Matrix7d::Identity();
    // Keypoints that scatter more than their covariances say (a real frontend's, a shape a
    // window got slightly wrong) widen the position's covariance by as much: the median
    // squared residual over its χ²₃ median.
    const double spread = squared.empty() ? 1.0 : std::max(1.0, Median(squared) / kChi2Median);
    *position_cov = spread * information.ldlt().solve(Matrix7d::Identity()).block<3, 3>(3, 3);
    return n;
  }

  // Levenberg–Marquardt with the Cauchy weights of each iterate (iteratively reweighted).
  ScaledPose Solve(ScaledPose body, double* cost) const {
    double current = Cost(body);
    double lambda = 1e-3;
    for (int iteration = 0; iteration < 30; ++iteration) {
      Matrix7d H = Matrix7d::Zero();
      Vector7d g = Vector7d::Zero();
      for (size_t i = 0; i < keypoints_.size(); ++i) {
        Eigen::Vector3d r;
        Eigen::Matrix<double, 3, 7> J;
        if (!Residual(i, body, &r, &J)) continue;
        const double s = r.dot(information_[i] * r);
        const double w = 1.0 / (1.0 + s / kCauchyScale);
        H += w * J.transpose() * information_[i] * J;
        g += w * J.transpose() * information_[i] * r;
      }
      bool improved = false;
      for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
        Matrix7d damped = H;
        damped.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
        const Vector7d step = -damped.ldlt().solve(g);
        if (!step.allFinite()) break;
        ScaledPose next = body;
        next.pose.linear() = ExpSO3(step.head<3>()) * body.pose.linear();
        next.pose.translation() += step.segment<3>(3);
        next.scale *= std::exp(step(6));
        const double c = Cost(next);
        if (c < current) {
          improved = true;
          const bool converged = current - c < 1e-9 * (1 + current) || step.norm() < 1e-7;
          body = next;
          current = c;
          lambda = std::max(lambda / 10, 1e-9);
          if (converged) iteration = 1000;
        } else {
          lambda *= 10;
        }
      }
      if (!improved) break;
    }
    *cost = current;
    return body;
  }

 private:
  const std::vector<BodyKeypoint>& keypoints_;
  const Pose cam_from_world_;
  const StereoCamera& camera_;
  std::vector<Eigen::Matrix3d> information_;
};

}  // namespace

std::optional<ObservedPose> ObserveBodyPose(const std::vector<BodyKeypoint>& keypoints,
                                            const std::vector<Eigen::Matrix3d>& rotations,
                                            const Pose& world_from_cam, const StereoCamera& camera,
                                            int min_inliers) {
  if (static_cast<int>(keypoints.size()) < std::max(min_inliers, 3) || rotations.empty())
    return std::nullopt;
  const PoseProblem problem(keypoints, world_from_cam, camera);
  std::optional<ObservedPose> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Eigen::Matrix3d& R : rotations) {
    std::vector<double> sx, sy, sz;
    for (const BodyKeypoint& k : keypoints) {
      Eigen::Vector3d p_cam;
      if (!camera.BackProject(k.x, &p_cam)) continue;
      const Eigen::Vector3d t = world_from_cam * p_cam - R * k.in_body;
      sx.push_back(t.x());
      sy.push_back(t.y());
      sz.push_back(t.z());
    }
    if (sx.empty()) continue;
    ScaledPose start;
    start.pose.linear() = R;
    start.pose.translation() = Eigen::Vector3d(Median(sx), Median(sy), Median(sz));
    double cost = 0;
    const ScaledPose solved = problem.Solve(start, &cost);
    if (cost < best_cost) {
      best_cost = cost;
      best = ObservedPose{solved.pose, 0, solved.scale, Eigen::Matrix3d::Identity()};
      best->inliers = problem.Inliers(solved, &best->position_cov);
    }
  }
  if (!best || best->inliers < min_inliers) return std::nullopt;
  return best;
}

}  // namespace cslam
