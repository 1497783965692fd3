#pragma once
// The Ceres side of the bundle adjustment (backend/bundle_adjustment.cc): the robust loss,
// the pose parameter blocks, the reprojection and motion-prior costs, and one solve's
// problem with what must outlive it. Internal to the backend library.
#include <ceres/ceres.h>
#include <ceres/product_manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "backend/bundle_adjustment.h"
#include "backend/motion_prior.h"
#include "backend/reprojection_error.h"
#include "backend/stereo_lm.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/spd3.h"
#include "core/task_runner.h"
#include "core/timer.h"

namespace cslam::ba_detail {


/// Dynamic covariance scaling (Agarwal et al., ICRA 2013) as an M-estimator: its IRLS weight
/// is the DCS scale² = (2Φ/(Φ+s))² for s > Φ, which integrates to ρ(s) = 3Φ − 4Φ²/(Φ+s).
class DcsLoss final : public ceres::LossFunction {
 public:
  explicit DcsLoss(double phi) : phi_(phi) {}
  void Evaluate(double s, double rho[3]) const override {
    if (s <= phi_) {
      rho[0] = s;
      rho[1] = 1.0;
      rho[2] = 0.0;
      return;
    }
    const double d = phi_ + s;
    rho[0] = 3.0 * phi_ - 4.0 * phi_ * phi_ / d;
    rho[1] = 4.0 * phi_ * phi_ / (d * d);
    rho[2] = -8.0 * phi_ * phi_ / (d * d * d);
  }

 private:
  double phi_;
};

/// A pose b_from_a as one Ceres block of 7: Eigen quaternion (x, y, z, w), then translation.
/// One block, not two [ours, measured]: the Schur elimination and the sparse normal equations
/// work per pair of parameter blocks a point links, so a point seen in n frames costs ~(2n)²/2
/// block updates with split blocks and n²/2 with one (docs/experiments/2026-12-01-batch-speed.md).
/// The tangent space (quaternion ⊕ R³) is the same, so are the steps.
struct PoseBlock {
  std::array<double, 7> x{0, 0, 0, 1, 0, 0, 0};

  double* data() { return x.data(); }
  const double* data() const { return x.data(); }
  static PoseBlock From(const Pose& pose) {
    PoseBlock b;
    const Eigen::Quaterniond q(pose.linear());
    const Eigen::Vector3d& t = pose.translation();
    b.x = {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
    return b;
  }
  Pose ToPose() const {
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::Quaterniond(x[3], x[0], x[1], x[2]).normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(x[4], x[5], x[6]);
    return pose;
  }
};

using PoseManifold = ceres::ProductManifold<ceres::EigenQuaternionManifold,
                                            ceres::EuclideanManifold<3>>;

/// Square root of the information: Lᵀ with Σ⁻¹ = L Lᵀ, so ‖Lᵀe‖² = eᵀΣ⁻¹e.
Eigen::Matrix3d SqrtInformation(const Eigen::Matrix3d& cov) {
  const Eigen::Matrix3d info = cov.inverse();
  return Eigen::LLT<Eigen::Matrix3d>(info).matrixL().transpose();
}

/// Whitened stereo reprojection error of a point in body frame b seen from camera c through
/// one pose cam_from_body (parameters: pose block (q, t), point).
struct ReprojectionCost {
  ReprojectionCost(const StereoCamera& camera, const Eigen::Vector3d& x,
                   const Eigen::Matrix3d& sqrt_info)
      : camera_(camera), x_(x), sqrt_info_(sqrt_info) {}

  template <typename T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(pose + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(point);
    const Eigen::Matrix<T, 3, 1> p_in_cam = rotation * p + translation;
    return Residual(p_in_cam, residual);
  }

  template <typename T>
  bool Residual(const Eigen::Matrix<T, 3, 1>& p_in_cam, T* residual) const {
    return WhitenedStereoResidual<T>(camera_, x_, sqrt_info_, p_in_cam, residual);
  }

  const StereoCamera& camera_;
  Eigen::Vector3d x_;
  Eigen::Matrix3d sqrt_info_;
};

/// ReprojectionCost with closed-form Jacobians (backend/reprojection_error.h).
class AnalyticReprojectionCost final : public ceres::SizedCostFunction<3, 7, 3> {
 public:
  explicit AnalyticReprojectionCost(const ReprojectionCost& cost) : cost_(cost) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double* d_pose = jacobians ? jacobians[0] : nullptr;
    double* d_point = jacobians ? jacobians[1] : nullptr;
    double d_q[12], d_t[9];
    if (!StereoReprojectionWithJacobians(cost_.camera_, cost_.x_, cost_.sqrt_info_,
                                         parameters[0], parameters[0] + 4, parameters[1],
                                         residuals, d_pose ? d_q : nullptr,
                                         d_pose ? d_t : nullptr, d_point))
      return false;
    if (d_pose)  // row-major 3×7 = [3×4 | 3×3]
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) d_pose[7 * r + c] = d_q[4 * r + c];
        for (int c = 0; c < 3; ++c) d_pose[7 * r + 4 + c] = d_t[3 * r + c];
      }
    return true;
  }

 private:
  ReprojectionCost cost_;
};

/// The coupled form of the moving-cluster residual: p_cam = cam_from_world · world_from_cluster ·
/// X.
struct CoupledReprojectionCost {
  explicit CoupledReprojectionCost(const ReprojectionCost& base) : base_(base) {}
  template <typename T>
  bool operator()(const T* cw, const T* wq, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> r_cw(cw), r_wq(wq);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tr_cw(cw + 4), tr_wq(wq + 4), p(point);
    const Eigen::Matrix<T, 3, 1> p_in_world = r_wq * p + tr_wq;
    return base_.Residual<T>(r_cw * p_in_world + tr_cw, residual);
  }
  ReprojectionCost base_;
};

/// MotionPriorResidual over three pose blocks, for Ceres.
struct MotionPriorCost {
  explicit MotionPriorCost(const MotionPriorTerm& term) : term_(term) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* residual) const {
    MotionPriorResidual(term_, a, b, c, residual);
    return true;
  }
  MotionPriorTerm term_;
};

/// Everything one Ceres solve needs that must outlive the Problem.
class Solve {
 public:
  Solve(const StereoCamera& camera, const BundleAdjustmentOptions& options, std::string label)
      : camera_(camera), options_(options), label_(std::move(label)) {
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(po);
    switch (options.robust_kernel) {
      case RobustKernel::kNone:
        break;
      case RobustKernel::kHuber:
        loss_ = std::make_unique<ceres::HuberLoss>(std::sqrt(options.robust_threshold_chi2));
        break;
      case RobustKernel::kDcs:
        loss_ = std::make_unique<DcsLoss>(options.robust_threshold_chi2);
        break;
    }
  }

  /// Observation of `point` through pose `cam_from_body`; skipped (false) when the point is
  /// not in front of the camera at the initial state. Kept until Run, which picks the solver.
  bool AddObservation(const StereoObservation& obs, PoseBlock* cam_from_body, double* point) {
    const ReprojectionCost cost(camera_, obs.x, SqrtInformation(obs.cov));
    Eigen::Vector3d r;
    if (!cost(cam_from_body->data(), point, r.data())) return false;
    pending_.push_back({cam_from_body, point, cost.sqrt_info_, obs.x});
    AddPose(cam_from_body);
    AddPoint(point);
    return true;
  }

  bool AddCoupledObservation(const StereoObservation& obs, PoseBlock* cam_from_world,
                             PoseBlock* world_from_cluster, double* point) {
    const CoupledReprojectionCost cost(ReprojectionCost(camera_, obs.x, SqrtInformation(obs.cov)));
    Eigen::Vector3d r;
    if (!cost(cam_from_world->data(), world_from_cluster->data(), point, r.data())) return false;
    coupled_ = true;
    problem_->AddResidualBlock(
        new ceres::AutoDiffCostFunction<CoupledReprojectionCost, 3, 7, 7, 3>(
            new CoupledReprojectionCost(cost)),
        loss_.get(), cam_from_world->data(), world_from_cluster->data(), point);
    AddPose(cam_from_world);
    AddPose(world_from_cluster);
    AddPoint(point);
    return true;
  }

  /// A constant-velocity prior on three poses already in the solve (by observations).
  void AddMotionPrior(PoseBlock* a, PoseBlock* b, PoseBlock* c, const MotionPriorTerm& term) {
    if (!Has(*a) || !Has(*b) || !Has(*c)) return;
    priors_.push_back({{a, b, c}, term});
  }

  bool Has(const PoseBlock& pose) const { return known_.count(pose.data()) > 0; }
  void HoldConstant(PoseBlock* pose) {
    if (!Has(*pose)) return;
    constant_.insert(pose->data());
    if (problem_->HasParameterBlock(pose->data()))
      problem_->SetParameterBlockConstant(pose->data());
  }

  /// Runs Levenberg–Marquardt; adds to `summary`.
  void Run(BundleAdjustmentSummary* summary) {
    if (pending_.empty() && priors_.empty() && problem_->NumResidualBlocks() == 0) return;
    const ceres::SparseLinearAlgebraLibraryType library =
        options_.sparse_library == SparseLibrary::kEigen ? ceres::EIGEN_SPARSE
                                                         : ceres::SUITE_SPARSE;
    const bool large = num_poses_ >= options_.sparse_schur_min_poses;
    const bool sparse = large && ceres::IsSparseLinearAlgebraLibraryTypeAvailable(library);
    if (!coupled_ && (large ? options_.native_sparse_solver : options_.native_dense_solver)) {
      RunNative(large, summary);
      return;
    }
    for (const Pending& o : pending_) {
      const ReprojectionCost cost(camera_, o.x, o.sqrt_info);
      ceres::CostFunction* function =
          options_.analytic_jacobians
              ? static_cast<ceres::CostFunction*>(new AnalyticReprojectionCost(cost))
              : new ceres::AutoDiffCostFunction<ReprojectionCost, 3, 7, 3>(
                    new ReprojectionCost(cost));
      problem_->AddResidualBlock(function, loss_.get(), o.pose->data(), o.point);
    }
    pending_.clear();
    for (const PendingPrior& prior : priors_)
      problem_->AddResidualBlock(
          new ceres::AutoDiffCostFunction<MotionPriorCost, 6, 7, 7, 7>(new MotionPriorCost(prior.term)),
          &prior_loss_, prior.poses[0]->data(), prior.poses[1]->data(), prior.poses[2]->data());
    for (double* pose : pose_blocks_) {
      if (problem_->GetManifold(pose) == nullptr) problem_->SetManifold(pose, &pose_manifold_);
      if (constant_.count(pose)) problem_->SetParameterBlockConstant(pose);
    }
    ceres::Solver::Options so;
    so.max_num_iterations = options_.max_iterations;
    so.function_tolerance = options_.function_tolerance;
    so.num_threads = options_.num_threads;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.linear_solver_type = ceres::DENSE_SCHUR;
    if (sparse) {
      switch (options_.sparse_solver) {
        case SparseSolver::kNormalCholesky:
          so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
          break;
        case SparseSolver::kSchur:
          so.linear_solver_type = ceres::SPARSE_SCHUR;
          break;
        case SparseSolver::kIterativeSchur:
          so.linear_solver_type = ceres::ITERATIVE_SCHUR;
          so.preconditioner_type = ceres::SCHUR_JACOBI;
          break;
      }
      so.sparse_linear_algebra_library_type = library;
    }
    // Schur solvers eliminate the points (group 0) first. Sparse normal Cholesky gets no
    // constraint [ours, measured]: CHOLMOD's minimum-degree ordering then eliminates whichever
    // side is cheaper — for a moving cluster of a few landmarks seen in many frames that is
    // the poses, leaving a tiny dense system on the points, where points-first filled a dense
    // 6·frames square (docs/experiments/2026-11-23-backend-speed.md). Same normal equations,
    // same steps.
    if (so.linear_solver_type != ceres::SPARSE_NORMAL_CHOLESKY ||
        options_.points_first_sparse_ordering) {
      const bool poses_first = so.linear_solver_type == ceres::DENSE_SCHUR &&
                               options_.dense_schur_smaller_side && !coupled_ &&
                               priors_.empty() &&  // priors couple poses: not eliminable first
                               3 * FreeBlocks(points_) < 6 * FreeBlocks(pose_blocks_);
      auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
      for (double* p : points_) ordering->AddElementToGroup(p, poses_first ? 1 : 0);
      for (double* p : pose_blocks_) ordering->AddElementToGroup(p, poses_first ? 0 : 1);
      so.linear_solver_ordering = ordering;
    }
    ceres::Solver::Summary s;
    ceres::Solve(so, problem_.get(), &s);
    auto log = GetLogger("backend");
    if (log->should_log(spdlog::level::debug)) {
      log->debug("BA solve {}: {} poses, {} points, {} residuals, {}, {} LM iterations ({} "
                 "accepted), cost {:.6g} -> {:.6g}, {}, {:.3f} s ({:.3f} s linear solver)",
                 label_, num_poses_, points_.size(), s.num_residual_blocks,
                 ceres::LinearSolverTypeToString(s.linear_solver_type_used),
                 s.num_successful_steps + s.num_unsuccessful_steps, s.num_successful_steps,
                 s.initial_cost, s.final_cost, ceres::TerminationTypeToString(s.termination_type),
                 s.total_time_in_seconds, s.linear_solver_time_in_seconds);
      if (log->should_log(spdlog::level::trace))
        for (const ceres::IterationSummary& it : s.iterations)
          log->trace("  {} it {:3d}: cost {:.9g} rel.decrease {:.3g} |g|max {:.3g} |step| {:.3g} "
                     "radius {:.3g} {}",
                     label_, it.iteration, it.cost, it.cost > 0 ? it.cost_change / it.cost : 0.0,
                     it.gradient_max_norm, it.step_norm, it.trust_region_radius,
                     it.step_is_successful ? "" : "(rejected)");
    }
    summary->iterations += static_cast<int>(s.iterations.size());
    ++summary->num_solves;
    MarkUnusable(s.termination_type == ceres::FAILURE ? "failed: " + s.message : "",
                 s.initial_cost, s.final_cost, summary);
  }

 private:
  /// A solve is not usable when it `failed` (non-empty: what happened) or ended at a
  /// non-finite cost or above where it started.
  void MarkUnusable(const std::string& failed, double initial_cost, double final_cost,
                    BundleAdjustmentSummary* summary) const {
    if (failed.empty() && std::isfinite(final_cost) && final_cost <= initial_cost) return;
    summary->usable = false;
    summary->why = "solve " + label_ + " " +
                   (failed.empty() ? "ended at cost " + std::to_string(final_cost) + " from " +
                                         std::to_string(initial_cost)
                                   : failed);
  }

  /// The same minimisation on backend/stereo_lm.h; `profile`: a large solve, factored by its
  /// profile.
  void RunNative(bool profile, BundleAdjustmentSummary* summary) {
    StereoLmProblem p;
    std::map<const double*, int> pose_index, point_index;
    std::vector<double*> poses = pose_blocks_;
    // The profile is narrow in frame order: a solve's poses are one frame-ordered array
    // (cam_from_world_ or one cluster's cam_from_cluster), so address order is frame order.
    if (profile) std::sort(poses.begin(), poses.end(), std::less<const double*>());
    for (double* pose : poses) {
      pose_index[pose] = static_cast<int>(p.poses.size());
      p.poses.push_back(pose);
      p.pose_free.push_back(constant_.count(pose) == 0);
    }
    for (double* point : points_) {
      point_index[point] = static_cast<int>(p.points.size());
      p.points.push_back(point);
    }
    p.residuals.reserve(pending_.size());
    for (const Pending& o : pending_)
      p.residuals.push_back({pose_index[o.pose->data()], point_index[o.point], o.x, o.sqrt_info});
    for (const PendingPrior& prior : priors_) {
      StereoLmPrior lp;
      for (int i = 0; i < 3; ++i) lp.pose[i] = pose_index[prior.poses[i]->data()];
      lp.term = prior.term;
      p.priors.push_back(lp);
    }
    StereoLmOptions lm;
    lm.kernel = options_.robust_kernel;
    lm.threshold_chi2 = options_.robust_threshold_chi2;
    lm.max_iterations = options_.max_iterations;
    lm.function_tolerance = options_.function_tolerance;
    lm.profile_cholesky = profile;
    const Timer timer;
    const StereoLmSummary s = SolveStereoLm(camera_, lm, &p);
    auto log = GetLogger("backend");
    if (log->should_log(spdlog::level::debug))
      log->debug("BA solve {}: {} poses, {} points, {} residuals, native {}, {} LM iterations "
                 "({} accepted), cost {:.6g} -> {:.6g}, {}, {:.3f} s",
                 label_, num_poses_, points_.size(), p.residuals.size(),
                 profile ? "profile" : "dense", s.iterations,
                 s.successful, s.initial_cost, s.final_cost,
                 s.converged ? "CONVERGENCE" : "NO_CONVERGENCE", timer.ElapsedS());
    summary->iterations += s.iterations + 1;  // Ceres counts its iteration 0 too
    ++summary->num_solves;
    MarkUnusable(s.failed ? "failed: a point is not in front of a camera" : "", s.initial_cost,
                 s.final_cost, summary);
  }

  int FreeBlocks(const std::vector<double*>& blocks) const {
    return static_cast<int>(std::count_if(blocks.begin(), blocks.end(), [this](double* b) {
      return !problem_->IsParameterBlockConstant(b);
    }));
  }
  void AddPose(PoseBlock* pose) {
    if (known_.insert(pose->data()).second) {
      pose_blocks_.push_back(pose->data());
      ++num_poses_;
    }
  }
  void AddPoint(double* point) {
    if (known_.insert(point).second) points_.push_back(point);
  }

  const StereoCamera& camera_;
  const BundleAdjustmentOptions& options_;
  std::string label_;  // names the solve in the debug log
  PoseManifold pose_manifold_;
  std::unique_ptr<ceres::LossFunction> loss_;
  std::unique_ptr<ceres::Problem> problem_;
  std::set<const double*> known_, constant_;
  /// A decoupled observation waiting for Run.
  struct Pending {
    PoseBlock* pose;
    double* point;
    Eigen::Matrix3d sqrt_info;
    Eigen::Vector3d x;
  };
  std::vector<Pending> pending_;
  /// A motion prior waiting for Run.
  struct PendingPrior {
    std::array<PoseBlock*, 3> poses;
    MotionPriorTerm term;
  };
  std::vector<PendingPrior> priors_;  // kept after Run adds them: they decide the ordering
  ceres::HuberLoss prior_loss_{std::sqrt(kMotionPriorHuberChi2)};
  std::vector<double*> points_, pose_blocks_;
  int num_poses_ = 0;
  bool coupled_ = false;  // a residual touches two poses: they are not independent
};

}  // namespace cslam::ba_detail
