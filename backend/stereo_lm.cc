#include "backend/stereo_lm.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "backend/reprojection_error.h"
#include "core/spd3.h"

namespace cslam {
namespace {

using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat63 = Eigen::Matrix<double, 6, 3>;
using Mat36 = Eigen::Matrix<double, 3, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// Ceres' defaults for what StereoLmOptions does not expose.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

/// ρ(s) and ρ'(s) of the kernel; the IRLS weight is ρ' (Ceres' corrector reduces to it when
/// ρ'' ≤ 0, which holds for Huber and DCS).
void Kernel(const StereoLmOptions& o, double s, double* rho, double* weight) {
  switch (o.kernel) {
    case RobustKernel::kNone:
      *rho = s;
      *weight = 1.0;
      return;
    case RobustKernel::kHuber: {
      const double b = o.threshold_chi2;
      if (s <= b) {
        *rho = s;
        *weight = 1.0;
      } else {
        const double r = std::sqrt(s);
        const double a = std::sqrt(b);
        *rho = 2.0 * a * r - b;
        *weight = a / r;
      }
      return;
    }
    case RobustKernel::kDcs: {
      const double phi = o.threshold_chi2;
      if (s <= phi) {
        *rho = s;
        *weight = 1.0;
      } else {
        const double d = phi + s;
        *rho = 3.0 * phi - 4.0 * phi * phi / d;
        *weight = 4.0 * phi * phi / (d * d);
      }
      return;
    }
  }
}

/// Factors the symmetric matrix whose upper triangle is in `s` as UᵀU, U upper, in place, by
/// block columns of size B. Block column j has no nonzero above block row first[j] (its
/// profile), and U keeps that profile (envelope Cholesky), so the work is Σ_j B·(B·(j −
/// first[j]))² instead of (dim)³/3. Reads and writes only the upper triangle within the profile.
template <int B>
bool ProfileCholesky(const std::vector<int>& first, Eigen::MatrixXd* s) {
  using MatB = Eigen::Matrix<double, B, B>;
  // Left-looking by B×B blocks: U_ij = U_iiᵀ⁻¹ (S_ij − Σ_k U_kiᵀ U_kj), k over the rows both
  // columns have. Each sum is B² dot products of contiguous columns; a triangular solve per
  // block column instead would repack the whole triangle above it every time.
  for (int j = 0; j < static_cast<int>(first.size()); ++j) {
    for (int i = first[j]; i <= j; ++i) {
      const int r0 = B * std::max(first[i], first[j]), n = B * i - r0;
      MatB x = s->template block<B, B>(B * i, B * j);
      if (n > 0)
        x.noalias() -= s->block(r0, B * i, n, B).transpose().lazyProduct(s->block(r0, B * j, n, B));
      if (i < j) {
        s->template block<B, B>(B * i, B * j) =
            s->template block<B, B>(B * i, B * i).transpose().template triangularView<Eigen::Lower>().solve(x);
      } else {
        const Eigen::LLT<MatB, Eigen::Upper> llt(x);
        if (llt.info() != Eigen::Success) return false;
        s->template block<B, B>(B * j, B * j) = llt.matrixU();
      }
    }
  }
  return true;
}

/// Solves UᵀU x = rhs with the upper factor of ProfileCholesky (zero outside the profile).
Eigen::VectorXd SolveFactored(const Eigen::MatrixXd& u, const Eigen::VectorXd& rhs) {
  Eigen::VectorXd x = rhs;
  u.triangularView<Eigen::Upper>().transpose().solveInPlace(x);
  u.triangularView<Eigen::Upper>().solveInPlace(x);
  return x;
}

/// The linearisation at the current state, kept while rejected steps re-solve it.
struct Linearisation {
  std::vector<Mat6> h_pose;             // [free pose]
  std::vector<Vec6> g_pose;
  std::vector<Mat3> h_point;            // [point]
  std::vector<Eigen::Vector3d> g_point;
  std::vector<Mat63> w;                 // [residual] J_poseᵀ J_point (weighted); zero if held
  /// Pose–pose blocks of the priors between two different free poses: (row, column, block)
  /// with row < column (the reduced system's upper triangle).
  std::vector<std::tuple<int, int, Mat6>> prior_pairs;
};

class Solver {
 public:
  Solver(const StereoCamera& camera, const StereoLmOptions& options, StereoLmProblem* problem)
      : camera_(camera), options_(options), p_(*problem) {
    free_index_.assign(p_.poses.size(), -1);
    for (size_t i = 0; i < p_.poses.size(); ++i)
      if (p_.pose_free[i]) free_index_[i] = num_free_++;
    // Residuals grouped by point (CSR) for the elimination.
    const int n = static_cast<int>(p_.points.size());
    start_.assign(n + 1, 0);
    for (const StereoLmResidual& r : p_.residuals) ++start_[r.point + 1];
    for (int i = 0; i < n; ++i) start_[i + 1] += start_[i];
    order_.resize(p_.residuals.size());
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t k = 0; k < p_.residuals.size(); ++k) order_[fill[p_.residuals[k].point]++] = static_cast<int>(k);
    // ... and, of those, the ones through free poses sorted by pose (the elimination's pairs).
    free_start_.assign(n + 1, 0);
    for (int l = 0; l < n; ++l) {
      free_start_[l + 1] = free_start_[l];
      for (int i = start_[l]; i < start_[l + 1]; ++i)
        if (free_index_[p_.residuals[order_[i]].pose] >= 0) {
          free_order_.push_back(order_[i]);
          ++free_start_[l + 1];
        }
      std::sort(free_order_.begin() + free_start_[l], free_order_.end(), [&](int a, int b) {
        return free_index_[p_.residuals[a].pose] < free_index_[p_.residuals[b].pose];
      });
    }
    // ... and the residuals through free poses grouped by pose.
    pose_start_.assign(num_free_ + 1, 0);
    for (const StereoLmResidual& r : p_.residuals)
      if (free_index_[r.pose] >= 0) ++pose_start_[free_index_[r.pose] + 1];
    for (int f = 0; f < num_free_; ++f) pose_start_[f + 1] += pose_start_[f];
    pose_order_.resize(pose_start_[num_free_]);
    fill.assign(pose_start_.begin(), pose_start_.end() - 1);
    for (size_t k = 0; k < p_.residuals.size(); ++k) {
      const int f = free_index_[p_.residuals[k].pose];
      if (f >= 0) pose_order_[fill[f]++] = static_cast<int>(k);
    }
    if (options_.profile_cholesky) ComputeProfiles();
  }

  /// The profiles of the two reduced systems: first_pose_[f], the lowest free pose that shares
  /// a point with free pose f; first_point_[l], the lowest point that shares a free pose with
  /// point l.
  void ComputeProfiles() {
    const int np = static_cast<int>(p_.points.size());
    std::vector<int> lowest_pose(np, num_free_), lowest_point(num_free_, np);
    for (const StereoLmResidual& r : p_.residuals) {
      const int f = free_index_[r.pose];
      if (f < 0) continue;
      lowest_pose[r.point] = std::min(lowest_pose[r.point], f);
      lowest_point[f] = std::min(lowest_point[f], r.point);
    }
    first_pose_.resize(num_free_);
    for (int f = 0; f < num_free_; ++f) first_pose_[f] = f;
    first_point_.resize(np);
    for (int l = 0; l < np; ++l) first_point_[l] = l;
    for (const StereoLmResidual& r : p_.residuals) {
      const int f = free_index_[r.pose];
      if (f < 0) continue;
      first_pose_[f] = std::min(first_pose_[f], lowest_pose[r.point]);
      first_point_[r.point] = std::min(first_point_[r.point], lowest_point[f]);
    }
    for (const StereoLmPrior& prior : p_.priors)
      for (int i : prior.pose)
        for (int j : prior.pose)
          if (free_index_[i] >= 0 && free_index_[j] >= 0)
            first_pose_[free_index_[i]] = std::min(first_pose_[free_index_[i]], free_index_[j]);
  }

  StereoLmSummary Run() {
    StereoLmSummary summary;
    double cost;
    if (!Cost(p_.poses, p_.points, &cost)) {
      summary.failed = true;
      return summary;
    }
    summary.initial_cost = summary.final_cost = cost;
    if (p_.residuals.empty() && p_.priors.empty()) return summary;
    double radius = kInitialRadius, decrease_factor = 2.0;
    Linearise();
    while (summary.iterations < options_.max_iterations) {
      if (MaxGradient() <= kGradientTolerance) {
        summary.converged = true;
        break;
      }
      ++summary.iterations;
      std::vector<Vec6> d_pose;
      std::vector<Eigen::Vector3d> d_point;
      double model_change = 0.0;
      const bool solved = SolveStep(1.0 / radius, &d_pose, &d_point, &model_change);
      double candidate_cost = 0.0;
      bool valid = solved && model_change > 0.0;
      if (valid) {
        if (StepNorm(d_pose, d_point) <= kParameterTolerance * (StateNorm() + kParameterTolerance)) {
          summary.converged = true;
          break;
        }
        Apply(d_pose, d_point);
        valid = Cost(candidate_poses_, candidate_points_, &candidate_cost);
      }
      if (valid && std::abs(cost - candidate_cost) <= options_.function_tolerance * cost) {
        if (candidate_cost < cost) {
          Commit();
          cost = candidate_cost;
          ++summary.successful;
        }
        summary.converged = true;
        break;
      }
      const double quality = valid ? (cost - candidate_cost) / model_change : -1.0;
      if (valid && quality > kMinRelativeDecrease) {
        Commit();
        cost = candidate_cost;
        ++summary.successful;
        radius = std::min(kMaxRadius,
                          radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3)));
        decrease_factor = 2.0;
        Linearise();
      } else {
        radius /= decrease_factor;
        decrease_factor *= 2.0;
        if (radius < kMinRadius) break;
      }
    }
    summary.final_cost = cost;
    return summary;
  }

 private:
  /// ½ Σ ρ(‖r‖²) at the given state; false when a point is behind a camera.
  bool Cost(const std::vector<double*>& poses, const std::vector<double*>& points,
            double* cost) const {
    double sum = 0.0;
    for (const StereoLmResidual& r : p_.residuals) {
      const double* pose = poses[r.pose];
      Eigen::Vector3d e;
      if (!StereoReprojectionWithJacobians(camera_, r.x, r.sqrt_info, pose, pose + 4,
                                           points[r.point], e.data(), nullptr, nullptr, nullptr))
        return false;
      double rho, weight;
      Kernel(options_, e.squaredNorm(), &rho, &weight);
      sum += rho;
    }
    for (const StereoLmPrior& prior : p_.priors) {
      Vec6 r;
      MotionPriorResidual(prior.term, poses[prior.pose[0]], poses[prior.pose[1]],
                          poses[prior.pose[2]], r.data());
      sum += PriorRho(r.squaredNorm());
    }
    *cost = 0.5 * sum;
    return true;
  }

  /// Huber on the prior's squared norm (motion_prior.h).
  static double PriorRho(double s, double* weight = nullptr) {
    const double b = kMotionPriorHuberChi2;
    if (s <= b) {
      if (weight) *weight = 1.0;
      return s;
    }
    const double r = std::sqrt(s), a = std::sqrt(b);
    if (weight) *weight = a / r;
    return 2.0 * a * r - b;
  }

  /// The priors' Jacobians by central differences in the solver's own tangent space (Apply:
  /// rotation perturbed on the left, translation added), added to the pose blocks.
  void LinearisePriors() {
    Linearisation& lin = lin_;
    lin.prior_pairs.clear();
    constexpr double kStep = 1e-6;
    for (const StereoLmPrior& prior : p_.priors) {
      std::array<std::array<double, 7>, 3> x;
      for (int i = 0; i < 3; ++i) std::copy(p_.poses[prior.pose[i]], p_.poses[prior.pose[i]] + 7, x[i].begin());
      const auto residual = [&](Vec6* r) {
        MotionPriorResidual(prior.term, x[0].data(), x[1].data(), x[2].data(), r->data());
      };
      Vec6 r0;
      residual(&r0);
      Mat6 jac[3];
      for (int i = 0; i < 3; ++i) {
        jac[i].setZero();
        if (free_index_[prior.pose[i]] < 0) continue;
        const std::array<double, 7> base = x[i];
        for (int k = 0; k < 6; ++k) {
          Vec6 plus, minus;
          for (const double sign : {1.0, -1.0}) {
            Vec6 d = Vec6::Zero();
            d(k) = sign * kStep;
            x[i] = base;
            Perturb(d, x[i].data());
            residual(sign > 0 ? &plus : &minus);
          }
          jac[i].col(k) = (plus - minus) / (2 * kStep);
        }
        x[i] = base;
      }
      double weight;  // IRLS, as the reprojection residuals' kernel
      PriorRho(r0.squaredNorm(), &weight);
      for (int i = 0; i < 3; ++i) {
        const int fi = free_index_[prior.pose[i]];
        if (fi < 0) continue;
        lin.g_pose[fi].noalias() += weight * jac[i].transpose() * r0;
        for (int j = 0; j < 3; ++j) {
          const int fj = free_index_[prior.pose[j]];
          if (fj < 0) continue;
          const Mat6 block = weight * jac[i].transpose() * jac[j];
          if (fi == fj)
            lin.h_pose[fi] += block;
          else if (fi < fj)
            lin.prior_pairs.emplace_back(fi, fj, block);
        }
      }
    }
  }

  /// x ⊞ d for one pose block: R ← Exp(φ) R, t ← t + δt.
  static void Perturb(const Vec6& d, double* pose) {
    const Eigen::Vector3d phi = d.head<3>();
    const double angle = phi.norm();
    const Eigen::Quaterniond dq = angle > 0
                                      ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle))
                                      : Eigen::Quaterniond::Identity();
    Eigen::Map<Eigen::Quaterniond> q(pose);
    q = (dq * q).normalized();
    for (int j = 0; j < 3; ++j) pose[4 + j] += d(3 + j);
  }

  void Linearise() {
    Linearisation& lin = lin_;
    lin.h_pose.assign(num_free_, Mat6::Zero());
    lin.g_pose.assign(num_free_, Vec6::Zero());
    lin.h_point.assign(p_.points.size(), Mat3::Zero());
    lin.g_point.assign(p_.points.size(), Eigen::Vector3d::Zero());
    lin.w.resize(p_.residuals.size());
    // Each pose's rotation matrix once: the quaternions are unit (Apply normalises; starts come
    // from rotation matrices), so ∂(q·X)/∂X = R. The residual's own Jacobian routine
    // (reprojection_error.h) differentiates the unnormalised quaternion product per residual,
    // which cost most of this loop.
    rotation_.resize(p_.poses.size());
    for (size_t i = 0; i < p_.poses.size(); ++i)
      rotation_[i] = Eigen::Map<const Eigen::Quaterniond>(p_.poses[i]).toRotationMatrix();
    const double fx = camera_.fx, fy = camera_.fy, fb = camera_.fx * camera_.baseline;
    for (size_t k = 0; k < p_.residuals.size(); ++k) {
      const StereoLmResidual& r = p_.residuals[k];
      const Mat3& rot = rotation_[r.pose];
      const Eigen::Vector3d rx = rot * Eigen::Map<const Eigen::Vector3d>(p_.points[r.point]);
      const Eigen::Vector3d pc = rx + Eigen::Map<const Eigen::Vector3d>(p_.poses[r.pose] + 4);
      // Cost() accepted this state, so every point is in front of its camera.
      const double inv_z = 1.0 / pc.z();
      const double u = pc.x() * inv_z, v = pc.y() * inv_z;
      const Eigen::Vector3d predicted(fx * u + camera_.cx, fy * v + camera_.cy,
                                      fx * u + camera_.cx - fb * inv_z);
      const Eigen::Vector3d e = r.sqrt_info * (r.x - predicted);
      Mat3 d_projection;
      d_projection << fx * inv_z, 0.0, -fx * u * inv_z,  //
          0.0, fy * inv_z, -fy * v * inv_z,              //
          fx * inv_z, 0.0, -(fx * u - fb * inv_z) * inv_z;
      const Mat3 d_cam = -r.sqrt_info * d_projection;  // ∂r/∂p_cam
      double rho, weight;
      Kernel(options_, e.squaredNorm(), &rho, &weight);
      // With D = d_cam, A = w DᵀD and b = w Dᵀe, the point's Jacobian D R and the pose's
      // D [−[rx]×  I] (left perturbation R ← Exp(φ) R) give every block from 3×3 products:
      // H_point = Rᵀ A R, g_point = Rᵀ b, W = [[rx]× A R; A R], g_pose = [rx × b; b],
      // H_pose = [[−[rx]× A [rx]×, [rx]× A], [(…)ᵀ, A]] — a third of the arithmetic of
      // forming the 3×6 and 3×3 Jacobians and multiplying them out.
      const Mat3 a = weight * d_cam.transpose() * d_cam;
      const Eigen::Vector3d b = weight * d_cam.transpose() * e;
      const Mat3 ar = a * rot;
      lin.h_point[r.point].noalias() += rot.transpose() * ar;
      lin.g_point[r.point].noalias() += rot.transpose() * b;
      const int f = free_index_[r.pose];
      if (f < 0) {
        lin.w[k].setZero();
        continue;
      }
      const Mat3 q = Skew(rx);
      const Mat3 qa = q * a;
      Mat6& h = lin.h_pose[f];
      h.topLeftCorner<3, 3>().noalias() -= qa * q;
      h.topRightCorner<3, 3>() += qa;
      h.bottomLeftCorner<3, 3>() += qa.transpose();
      h.bottomRightCorner<3, 3>() += a;
      lin.g_pose[f].head<3>() += rx.cross(b);
      lin.g_pose[f].tail<3>() += b;
      lin.w[k].topRows<3>().noalias() = q * ar;
      lin.w[k].bottomRows<3>() = ar;
    }
    LinearisePriors();
  }

  static Mat3 Skew(const Eigen::Vector3d& v) {
    Mat3 s;
    s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return s;
  }

  static double Damping(double h, double mu) {
    return std::clamp(h, kMinDiagonal, kMaxDiagonal) * mu;
  }

  /// Solves (H + μ diag H) δ = −g by eliminating the points; false if the reduced camera
  /// system is not positive definite. `model_change` = L(0) − L(δ) of the linear model.
  bool SolveStep(double mu, std::vector<Vec6>* d_pose, std::vector<Eigen::Vector3d>* d_point,
                 double* model_change) const {
    // Every residual touches one pose, so either side can be eliminated; factor the smaller
    // reduced system (a moving cluster: a few points in 30 frames).
    const int np = static_cast<int>(p_.points.size());
    const bool ok = 3 * np < 6 * num_free_ && p_.priors.empty()
                        ? EliminatePoses(mu, d_pose, d_point)
                        : EliminatePoints(mu, d_pose, d_point);
    if (!ok) return false;
    const Linearisation& lin = lin_;
    // (H + D) δ = −g, so δᵀHδ = −gᵀδ − δᵀDδ and L(0) − L(δ) = −gᵀδ − ½δᵀHδ = ½(δᵀDδ − gᵀδ).
    double g_dot = 0.0, d_dot = 0.0;
    for (int f = 0; f < num_free_; ++f) {
      const Vec6& d = (*d_pose)[f];
      g_dot += lin.g_pose[f].dot(d);
      for (int j = 0; j < 6; ++j) d_dot += Damping(lin.h_pose[f](j, j), mu) * d(j) * d(j);
    }
    for (int l = 0; l < np; ++l) {
      const Eigen::Vector3d& d = (*d_point)[l];
      g_dot += lin.g_point[l].dot(d);
      for (int j = 0; j < 3; ++j) d_dot += Damping(lin.h_point[l](j, j), mu) * d(j) * d(j);
    }
    *model_change = 0.5 * (d_dot - g_dot);
    return std::isfinite(*model_change);
  }

  /// Points eliminated: a dense 6·(free poses) system.
  bool EliminatePoints(double mu, std::vector<Vec6>* d_pose,
                       std::vector<Eigen::Vector3d>* d_point) const {
    const Linearisation& lin = lin_;
    const int np = static_cast<int>(p_.points.size());
    const int m = 6 * num_free_;
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd rhs(m);
    for (int f = 0; f < num_free_; ++f) {
      Mat6 h = lin.h_pose[f];
      for (int j = 0; j < 6; ++j) h(j, j) += Damping(h(j, j), mu);
      s.block<6, 6>(6 * f, 6 * f) = h;
      rhs.segment<6>(6 * f) = -lin.g_pose[f];
    }
    for (const auto& [row, col, block] : lin.prior_pairs) s.block<6, 6>(6 * row, 6 * col) += block;
    std::vector<Mat3> inv(np);
    std::vector<Mat63> v;
    for (int l = 0; l < np; ++l) {
      Mat3 a = lin.h_point[l];
      for (int j = 0; j < 3; ++j) a(j, j) += Damping(a(j, j), mu);
      double det;
      if (!InvertSpd3(a, &inv[l], &det)) return false;
      v.clear();
      const Eigen::Vector3d gl = -lin.g_point[l];
      // The point's residuals through free poses in ascending pose order (free_order_), so
      // that the upper triangle S_ab −= V_a W_bᵀ, b ≥ a, is the pairs j ≥ i.
      const int* begin = free_order_.data() + free_start_[l];
      const int count = free_start_[l + 1] - free_start_[l];
      for (int i = 0; i < count; ++i) {
        const int k = begin[i];
        v.push_back(lin.w[k] * inv[l]);
        rhs.segment<6>(6 * free_index_[p_.residuals[k].pose]).noalias() -= v.back() * gl;
      }
      for (int i = 0; i < count; ++i) {
        const int fa = free_index_[p_.residuals[begin[i]].pose];
        for (int j = i; j < count; ++j) {
          const int kb = begin[j];
          const int fb = free_index_[p_.residuals[kb].pose];
          s.block<6, 6>(6 * fa, 6 * fb).noalias() -= v[i] * lin.w[kb].transpose();
        }
      }
    }
    d_pose->assign(num_free_, Vec6::Zero());
    if (m > 0) {
      Eigen::VectorXd x;
      if (!SolveReduced<6>(first_pose_, &s, rhs, &x)) return false;
      for (int f = 0; f < num_free_; ++f) (*d_pose)[f] = x.segment<6>(6 * f);
    }
    d_point->assign(np, Eigen::Vector3d::Zero());
    for (int l = 0; l < np; ++l) {
      Eigen::Vector3d b = -lin.g_point[l];
      for (int i = start_[l]; i < start_[l + 1]; ++i) {
        const int k = order_[i];
        const int f = free_index_[p_.residuals[k].pose];
        if (f >= 0) b.noalias() -= lin.w[k].transpose() * (*d_pose)[f];
      }
      (*d_point)[l] = inv[l] * b;
    }
    return true;
  }

  /// Solves the reduced system `s` x = `rhs` (upper triangle filled; overwritten by its
  /// factor) by its profile of B-blocks `first` or by a dense LLT; false unless x is finite.
  template <int B>
  bool SolveReduced(const std::vector<int>& first, Eigen::MatrixXd* s, const Eigen::VectorXd& rhs,
                    Eigen::VectorXd* x) const {
    if (options_.profile_cholesky) {
      if (!ProfileCholesky<B>(first, s)) return false;
      *x = SolveFactored(*s, rhs);
    } else {
      const Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> llt(*s);
      if (llt.info() != Eigen::Success) return false;
      *x = llt.solve(rhs);
    }
    return x->allFinite();
  }

  /// Free poses eliminated: a dense 3·points system.
  bool EliminatePoses(double mu, std::vector<Vec6>* d_pose,
                      std::vector<Eigen::Vector3d>* d_point) const {
    const Linearisation& lin = lin_;
    const int np = static_cast<int>(p_.points.size());
    const int m = 3 * np;
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd rhs(m);
    for (int l = 0; l < np; ++l) {
      Mat3 a = lin.h_point[l];
      for (int j = 0; j < 3; ++j) a(j, j) += Damping(a(j, j), mu);
      s.block<3, 3>(3 * l, 3 * l) = a;
      rhs.segment<3>(3 * l) = -lin.g_point[l];
    }
    std::vector<Mat6> inv(num_free_);
    std::vector<Mat36> u;
    for (int f = 0; f < num_free_; ++f) {
      Mat6 b = lin.h_pose[f];
      for (int j = 0; j < 6; ++j) b(j, j) += Damping(b(j, j), mu);
      Eigen::LLT<Mat6> llt(b);
      if (llt.info() != Eigen::Success) return false;
      inv[f] = llt.solve(Mat6::Identity());
      u.clear();
      const Vec6 gf = -lin.g_pose[f];
      for (int i = pose_start_[f]; i < pose_start_[f + 1]; ++i) {
        const int k = pose_order_[i];
        u.push_back(lin.w[k].transpose() * inv[f]);
        rhs.segment<3>(3 * p_.residuals[k].point).noalias() -= u.back() * gf;
      }
      // S_ab −= U_a W_b over the pose's observed point pairs (upper triangle).
      for (int i = pose_start_[f]; i < pose_start_[f + 1]; ++i) {
        const int la = p_.residuals[pose_order_[i]].point;
        for (int j = pose_start_[f]; j < pose_start_[f + 1]; ++j) {
          const int kb = pose_order_[j];
          const int lb = p_.residuals[kb].point;
          if (lb >= la)
            s.block<3, 3>(3 * la, 3 * lb).noalias() -= u[i - pose_start_[f]] * lin.w[kb];
        }
      }
    }
    Eigen::VectorXd x;
    if (!SolveReduced<3>(first_point_, &s, rhs, &x)) return false;
    d_point->assign(np, Eigen::Vector3d::Zero());
    for (int l = 0; l < np; ++l) (*d_point)[l] = x.segment<3>(3 * l);
    d_pose->assign(num_free_, Vec6::Zero());
    for (int f = 0; f < num_free_; ++f) {
      Vec6 b = -lin.g_pose[f];
      for (int i = pose_start_[f]; i < pose_start_[f + 1]; ++i) {
        const int k = pose_order_[i];
        b.noalias() -= lin.w[k] * (*d_point)[p_.residuals[k].point];
      }
      (*d_pose)[f] = inv[f] * b;
    }
    return true;
  }

  /// The candidate state x ⊞ δ in scratch storage (the problem keeps x until Commit).
  void Apply(const std::vector<Vec6>& d_pose, const std::vector<Eigen::Vector3d>& d_point) {
    pose_store_.resize(p_.poses.size());
    candidate_poses_.resize(p_.poses.size());
    for (size_t i = 0; i < p_.poses.size(); ++i) {
      std::copy(p_.poses[i], p_.poses[i] + 7, pose_store_[i].begin());
      candidate_poses_[i] = pose_store_[i].data();
      const int f = free_index_[i];
      if (f < 0) continue;
      Perturb(d_pose[f], pose_store_[i].data());
    }
    point_store_.resize(p_.points.size());
    candidate_points_.resize(p_.points.size());
    for (size_t l = 0; l < p_.points.size(); ++l) {
      for (int j = 0; j < 3; ++j) point_store_[l][j] = p_.points[l][j] + d_point[l](j);
      candidate_points_[l] = point_store_[l].data();
    }
  }

  void Commit() {
    for (size_t i = 0; i < p_.poses.size(); ++i)
      std::copy(pose_store_[i].begin(), pose_store_[i].end(), p_.poses[i]);
    for (size_t l = 0; l < p_.points.size(); ++l)
      std::copy(point_store_[l].begin(), point_store_[l].end(), p_.points[l]);
  }

  double MaxGradient() const {
    double g = 0.0;
    for (const Vec6& v : lin_.g_pose) g = std::max(g, v.cwiseAbs().maxCoeff());
    for (const Eigen::Vector3d& v : lin_.g_point) g = std::max(g, v.cwiseAbs().maxCoeff());
    return g;
  }

  static double StepNorm(const std::vector<Vec6>& d_pose,
                         const std::vector<Eigen::Vector3d>& d_point) {
    double s = 0.0;
    for (const Vec6& d : d_pose) s += d.squaredNorm();
    for (const Eigen::Vector3d& d : d_point) s += d.squaredNorm();
    return std::sqrt(s);
  }

  double StateNorm() const {
    double s = 0.0;
    for (size_t i = 0; i < p_.poses.size(); ++i)
      if (free_index_[i] >= 0)
        for (int j = 0; j < 7; ++j) s += p_.poses[i][j] * p_.poses[i][j];
    for (const double* x : p_.points)
      for (int j = 0; j < 3; ++j) s += x[j] * x[j];
    return std::sqrt(s);
  }

  const StereoCamera& camera_;
  const StereoLmOptions& options_;
  StereoLmProblem& p_;
  std::vector<int> free_index_;  // [pose] → index among the free poses, or −1
  int num_free_ = 0;
  std::vector<int> start_, order_;  // residuals by point
  std::vector<int> free_start_, free_order_;  // residuals through free poses, by point and pose
  std::vector<int> pose_start_, pose_order_;  // residuals through free poses, by free pose
  std::vector<int> first_pose_, first_point_;  // profiles (ComputeProfiles)
  Linearisation lin_;
  std::vector<Mat3> rotation_;  // [pose] at the linearisation point
  std::vector<std::array<double, 7>> pose_store_;
  std::vector<std::array<double, 3>> point_store_;
  std::vector<double*> candidate_poses_, candidate_points_;
};

}  // namespace

StereoLmSummary SolveStereoLm(const StereoCamera& camera, const StereoLmOptions& options,
                              StereoLmProblem* problem) {
  return Solver(camera, options, problem).Run();
}

}  // namespace cslam
