#include "backend/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/product_manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <functional>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>

#include "backend/reprojection_error.h"
#include "backend/stereo_lm.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/spd3.h"
#include "core/task_runner.h"
#include "core/timer.h"

namespace cslam {

std::string ToString(RobustKernel kernel) {
  switch (kernel) {
    case RobustKernel::kNone:
      return "none";
    case RobustKernel::kHuber:
      return "huber";
    case RobustKernel::kDcs:
      return "dcs";
  }
  return "?";
}

RobustKernel ParseRobustKernel(const std::string& text, const std::string& key) {
  if (text == "none") return RobustKernel::kNone;
  if (text == "huber") return RobustKernel::kHuber;
  if (text == "dcs") return RobustKernel::kDcs;
  throw ConfigError(key + ": must be one of none, huber, dcs, got '" + text + "'");
}

std::string ToString(SparseSolver solver) {
  switch (solver) {
    case SparseSolver::kNormalCholesky:
      return "normal_cholesky";
    case SparseSolver::kSchur:
      return "schur";
    case SparseSolver::kIterativeSchur:
      return "iterative_schur";
  }
  return "?";
}

SparseSolver ParseSparseSolver(const std::string& text, const std::string& key) {
  if (text == "schur") return SparseSolver::kSchur;
  if (text == "normal_cholesky") return SparseSolver::kNormalCholesky;
  if (text == "iterative_schur") return SparseSolver::kIterativeSchur;
  throw ConfigError(key + ": must be one of normal_cholesky, schur, iterative_schur, got '" +
                    text + "'");
}

std::string ToString(SparseLibrary library) {
  return library == SparseLibrary::kEigen ? "eigen" : "suite_sparse";
}

SparseLibrary ParseSparseLibrary(const std::string& text, const std::string& key) {
  if (text == "suite_sparse") return SparseLibrary::kSuiteSparse;
  if (text == "eigen") return SparseLibrary::kEigen;
  throw ConfigError(key + ": must be one of suite_sparse, eigen, got '" + text + "'");
}

std::string ToString(BaCoupling coupling) {
  switch (coupling) {
    case BaCoupling::kDecoupled:
      return "decoupled";
    case BaCoupling::kSemiCoupled:
      return "semi_coupled";
    case BaCoupling::kFullyCoupled:
      return "fully_coupled";
  }
  return "?";
}

BaCoupling ParseBaCoupling(const std::string& text, const std::string& key) {
  if (text == "decoupled") return BaCoupling::kDecoupled;
  if (text == "semi_coupled") return BaCoupling::kSemiCoupled;
  if (text == "fully_coupled") return BaCoupling::kFullyCoupled;
  throw ConfigError(key + ": must be one of decoupled, semi_coupled, fully_coupled, got '" + text +
                    "'");
}

void BundleAdjustmentOptions::Check() const {
  CheckOption(robust_threshold_chi2 > 0, "robust_threshold_chi2", "must be > 0",
              robust_threshold_chi2);
  CheckOption(max_iterations >= 0, "max_iterations", "must be >= 0", max_iterations);
  CheckOption(moving_max_iterations >= -1, "moving_max_iterations",
              "must be >= 0 (-1: max_iterations)", moving_max_iterations);
  CheckOption(function_tolerance > 0, "function_tolerance", "must be > 0", function_tolerance);
  CheckOption(num_threads >= 1, "num_threads", "must be >= 1", num_threads);
  CheckOption(min_observations_per_pose >= 1, "min_observations_per_pose", "must be >= 1",
              min_observations_per_pose);
  CheckOption(sparse_schur_min_poses >= 0, "sparse_schur_min_poses", "must be >= 0",
              sparse_schur_min_poses);
  CheckOption(std::isfinite(far_depth_baselines) && far_depth_baselines >= 0, "far_depth_baselines",
              "must be >= 0 baselines (0 = off)", far_depth_baselines);
  CheckOption(std::isfinite(far_disparity_sigma_px) && far_disparity_sigma_px > 0,
              "far_disparity_sigma_px", "must be > 0 px", far_disparity_sigma_px);
  CheckOption(std::isfinite(motion_prior_sigma_m) && motion_prior_sigma_m >= 0,
              "motion_prior_sigma_m", "must be >= 0 m (0 = off)", motion_prior_sigma_m);
  CheckOption(std::isfinite(motion_prior_sigma_rad) && motion_prior_sigma_rad >= 0,
              "motion_prior_sigma_rad", "must be >= 0 rad (0 = off)", motion_prior_sigma_rad);
  CheckOption((motion_prior_sigma_m > 0) == (motion_prior_sigma_rad > 0), "motion_prior_sigma_rad",
              "must be > 0 exactly when motion_prior_sigma_m is (both 0 turns the prior off)",
              motion_prior_sigma_rad);
}

void BundleAdjustmentOptions::Load(OptionsReader& reader) {
  std::string coupling_text = ToString(coupling);
  reader.Read("coupling", &coupling_text);
  coupling = ParseBaCoupling(coupling_text, reader.Where("coupling"));
  std::string kernel_text = ToString(robust_kernel);
  reader.Read("robust_kernel", &kernel_text);
  robust_kernel = ParseRobustKernel(kernel_text, reader.Where("robust_kernel"));
  reader.Read("robust_threshold_chi2", &robust_threshold_chi2);
  reader.Read("max_iterations", &max_iterations);
  reader.Read("moving_max_iterations", &moving_max_iterations);
  reader.Read("function_tolerance", &function_tolerance);
  reader.Read("num_threads", &num_threads);
  reader.Read("min_observations_per_pose", &min_observations_per_pose);
  reader.Read("sparse_schur_min_poses", &sparse_schur_min_poses);
  reader.Read("far_depth_baselines", &far_depth_baselines);
  reader.Read("far_disparity_sigma_px", &far_disparity_sigma_px);
  reader.Read("motion_prior_sigma_m", &motion_prior_sigma_m);
  reader.Read("motion_prior_sigma_rad", &motion_prior_sigma_rad);
  reader.Read("points_first_sparse_ordering", &points_first_sparse_ordering);
  reader.Read("analytic_jacobians", &analytic_jacobians);
  reader.Read("dense_schur_smaller_side", &dense_schur_smaller_side);
  reader.Read("native_dense_solver", &native_dense_solver);
  reader.Read("native_sparse_solver", &native_sparse_solver);
  std::string solver_text = ToString(sparse_solver);
  reader.Read("sparse_solver", &solver_text);
  sparse_solver = ParseSparseSolver(solver_text, reader.Where("sparse_solver"));
  std::string library_text = ToString(sparse_library);
  reader.Read("sparse_library", &library_text);
  sparse_library = ParseSparseLibrary(library_text, reader.Where("sparse_library"));
}

namespace {

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

/// Counts observations per pose block so that poorly observed poses can be held.
using ObservationCount = std::map<const PoseBlock*, int>;

void HoldWeakPoses(std::vector<PoseBlock>& poses, const ObservationCount& counts, int min_count,
                   Solve* solve) {
  for (PoseBlock& pose : poses) {
    auto it = counts.find(&pose);
    if (it != counts.end() && it->second < min_count) solve->HoldConstant(&pose);
  }
}

/// The per-frame data of one moving cluster while it is being adjusted.
struct ClusterState {
  ClusterMotion* motion;
  std::vector<int> frame_index;  // [frame - range.begin] → index in motion->frames, or -1
  std::vector<PoseBlock> cam_from_cluster;
  std::vector<PoseBlock> world_from_cluster;  // coupled modes only
};

class Adjuster {
 public:
  Adjuster(const TrackletTable& table, const StereoCamera& camera,
           const BundleAdjustmentOptions& options, MotionEstimate* estimate,
           const std::vector<bool>* held_out, const std::vector<bool>* fixed_cameras,
           bool clusters_only = false)
      : table_(table), camera_(camera), options_(options), est_(*estimate),
        clusters_only_(clusters_only) {
    if (held_out) held_out_ = *held_out;
    if (fixed_cameras) fixed_cameras_ = *fixed_cameras;
    fixed_cameras_.resize(est_.world_from_cam.size(), false);
    any_fixed_camera_ = std::find(fixed_cameras_.begin(), fixed_cameras_.end(), true) != fixed_cameras_.end();
    held_out_.resize(est_.landmark_in_cluster.size(), false);
    const FrameRange range = est_.range;
    for (const Pose& world_from_cam : est_.world_from_cam)
      cam_from_world_.push_back(PoseBlock::From(world_from_cam.inverse()));
    points_.resize(est_.landmark_in_cluster.size());
    for (size_t i = 0; i < points_.size(); ++i)
      for (int k = 0; k < 3; ++k) points_[i][k] = est_.landmark_in_cluster[i](k);
    for (ClusterMotion& motion : est_.clusters) {
      ClusterState cs{&motion, std::vector<int>(range.size(), -1), {}, {}};
      for (size_t k = 0; k < motion.frames.size(); ++k) {
        cs.frame_index[motion.frames[k] - range.begin] = static_cast<int>(k);
        cs.cam_from_cluster.push_back(PoseBlock::From(motion.cam_from_cluster[k]));
      }
      cluster_of_label_[motion.cluster] = static_cast<int>(clusters_.size());
      clusters_.push_back(std::move(cs));
    }
  }

  BundleAdjustmentSummary Run() {
    BundleAdjustmentSummary summary;
    if (clusters_only_ || options_.coupling == BaCoupling::kDecoupled) {
      // Step (1) and step (2) share no unknowns: every moving cluster's solve and the static
      // one may run side by side (options.runner). Each writes only its own poses and points
      // and its own summary, merged in a fixed order, so the result does not depend on the
      // runner. The static solve, the largest, is task 0 so that it starts first;
      // AdjustClusterMotions runs step (1) alone.
      const int n = static_cast<int>(clusters_.size());
      const int first_cluster_task = clusters_only_ ? 0 : 1;
      std::vector<BundleAdjustmentSummary> parts(n + 1);
      RunTasks(options_.runner.get(), n + first_cluster_task, [&](int task) {
        if (task < first_cluster_task)
          SolveStatic(&parts[n]);
        else
          SolveCluster(&clusters_[task - first_cluster_task], &parts[task - first_cluster_task]);
      });
      for (const BundleAdjustmentSummary& part : parts) {
        summary.iterations += part.iterations;
        summary.num_solves += part.num_solves;
        if (!part.usable && summary.usable) summary.why = part.why;
        summary.usable = summary.usable && part.usable;
      }
    } else {
      if (options_.coupling != BaCoupling::kFullyCoupled)
        for (ClusterState& cs : clusters_) SolveCluster(&cs, &summary);
      SolveCoupled(&summary);
    }
    WriteBack();
    return summary;
  }

 private:
  bool Usable(int landmark) const {
    return est_.landmark_cluster[landmark] >= 0 && est_.landmark_in_cluster[landmark].allFinite();
  }
  /// A landmark that enters the solves.
  bool Adjusted(int landmark) const { return Usable(landmark) && !held_out_[landmark]; }

  /// Step (1): one moving cluster's landmarks and per-frame T^{cq}_t.
  void SolveCluster(ClusterState* cs, BundleAdjustmentSummary* summary) {
    const int label = cs->motion->cluster;
    BundleAdjustmentOptions options = options_;
    if (options.moving_max_iterations >= 0) options.max_iterations = options.moving_max_iterations;
    Solve solve(camera_, options, "cluster " + std::to_string(label));
    ObservationCount counts;
    for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
      if (est_.landmark_cluster[i] != label || !Adjusted(i)) continue;
      for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
        const int k = cs->frame_index[obs.frame - est_.range.begin];
        if (k < 0) continue;
        if (solve.AddObservation(obs, &cs->cam_from_cluster[k], points_[i].data()))
          ++counts[&cs->cam_from_cluster[k]];
      }
    }
    HoldWeakPoses(cs->cam_from_cluster, counts, options_.min_observations_per_pose, &solve);
    if (options_.motion_prior_sigma_m > 0) AddMotionPriors(cs, label, counts, &solve);
    // Gauge: the cluster's frame is arbitrary up to SE(3); hold its first well-seen pose.
    for (PoseBlock& pose : cs->cam_from_cluster) {
      auto it = counts.find(&pose);
      if (it != counts.end() && it->second >= options_.min_observations_per_pose) {
        solve.HoldConstant(&pose);
        break;
      }
    }
    solve.Run(summary);
  }

  /// The constant-velocity prior (motion_prior_sigma_m) on every three consecutive frames
  /// whose poses the solve estimates (held weak poses would pull their neighbours towards
  /// their unrefined values). Camera poses are the solve's input: the static solve refines
  /// them at the same time, by centimetres against the prior's decimetres.
  void AddMotionPriors(ClusterState* cs, int label, const ObservationCount& counts, Solve* solve) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    int n = 0;
    for (int i = 0; i < static_cast<int>(points_.size()); ++i)
      if (est_.landmark_cluster[i] == label && Adjusted(i)) {
        centre += Eigen::Map<const Eigen::Vector3d>(points_[i].data());
        ++n;
      }
    if (n == 0) return;
    centre /= n;
    const auto well_seen = [&](int k) {
      const auto it = counts.find(&cs->cam_from_cluster[k]);
      return it != counts.end() && it->second >= options_.min_observations_per_pose;
    };
    const std::vector<int>& frames = cs->motion->frames;
    for (size_t k = 0; k + 2 < frames.size(); ++k) {
      if (frames[k + 1] != frames[k] + 1 || frames[k + 2] != frames[k] + 2) continue;
      if (!well_seen(k) || !well_seen(k + 1) || !well_seen(k + 2)) continue;
      MotionPriorTerm term;
      for (int i = 0; i < 3; ++i) term.world_from_cam[i] = est_.world_from_cam[frames[k + i] - est_.range.begin];
      term.centre = centre;
      term.sigma_m = options_.motion_prior_sigma_m;
      term.sigma_rad = options_.motion_prior_sigma_rad;
      solve->AddMotionPrior(&cs->cam_from_cluster[k], &cs->cam_from_cluster[k + 1],
                            &cs->cam_from_cluster[k + 2], term);
    }
  }

  /// Step (2) of the decoupled scheme: camera poses and static landmarks.
  void SolveStatic(BundleAdjustmentSummary* summary) {
    Solve solve(camera_, options_, "static");
    ObservationCount counts;
    AddStatic(&solve, &counts);
    HoldWeakPoses(cam_from_world_, counts, options_.min_observations_per_pose, &solve);
    HoldFixedCameras(&solve);
    if (!cam_from_world_.empty()) solve.HoldConstant(&cam_from_world_[0]);
    solve.Run(summary);
  }

  void HoldFixedCameras(Solve* solve) {
    for (size_t f = 0; f < cam_from_world_.size(); ++f)
      if (fixed_cameras_[f]) solve->HoldConstant(&cam_from_world_[f]);
  }

  /// A camera pose no solve moves: the gauge frame or a fixed one.
  bool HeldCamera(int frame) const { return frame == 0 || fixed_cameras_[frame]; }

  /// A static landmark that only held cameras observe is decoupled from every free unknown
  /// (its residuals involve no other parameter), so leaving it out changes no pose or other
  /// point; it keeps its position — in a warm window the map's, refined in the window where
  /// its frames were new. Most of a warm window's static landmarks are such (KITTI: ~2/3).
  bool OnlyHeldCamerasSee(int landmark) const {
    if (!any_fixed_camera_) return false;
    for (const StereoObservation& obs : table_.ObservationsOf(landmark, est_.range))
      if (!HeldCamera(obs.frame - est_.range.begin)) return false;
    return true;
  }

  /// Whether `point`, at its current estimate, is farther from the camera than
  /// far_depth_baselines (BundleAdjustmentOptions). The current depth, not the observation's
  /// own disparity, decides: choosing by the noisy measurement would keep exactly the
  /// observations whose noise enlarged the disparity, a bias towards near depths (measured: it
  /// shortened the generated outdoor sequences' scale;
  /// docs/experiments/2026-12-02-far-points-without-disparity.md).
  bool FarFrom(const PoseBlock& cam_from_world, const double* point) const {
    if (options_.far_depth_baselines <= 0) return false;
    const Eigen::Map<const Eigen::Quaterniond> q(cam_from_world.data());
    const double depth = (q * Eigen::Map<const Eigen::Vector3d>(point)).z() + cam_from_world.x[6];
    return depth > options_.far_depth_baselines * camera_.baseline;
  }

  void AddStatic(Solve* solve, ObservationCount* counts) {
    for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
      if (est_.landmark_cluster[i] != 0 || !Adjusted(i) || OnlyHeldCamerasSee(i)) continue;
      for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
        PoseBlock* pose = &cam_from_world_[obs.frame - est_.range.begin];
        const StereoObservation* use = &obs;
        StereoObservation far;
        if (FarFrom(*pose, points_[i].data())) {
          far = obs;
          far.cov(2, 2) += options_.far_disparity_sigma_px * options_.far_disparity_sigma_px;
          use = &far;
        }
        if (solve->AddObservation(*use, pose, points_[i].data())) ++(*counts)[pose];
      }
    }
  }

  /// The whole E: camera, static landmarks, and every moving cluster through P^q_t. A moving
  /// cluster's own SE(3) gauge is left to the Levenberg–Marquardt damping: holding one of its
  /// world poses would make that frame's observations pull on the camera pose.
  void SolveCoupled(BundleAdjustmentSummary* summary) {
    Solve solve(camera_, options_, "coupled");
    ObservationCount counts;
    AddStatic(&solve, &counts);
    for (ClusterState& cs : clusters_) {
      cs.world_from_cluster.clear();
      for (size_t k = 0; k < cs.motion->frames.size(); ++k) {
        const int f = cs.motion->frames[k] - est_.range.begin;
        cs.world_from_cluster.push_back(PoseBlock::From(cam_from_world_[f].ToPose().inverse() *
                                                        cs.cam_from_cluster[k].ToPose()));
      }
      const int label = cs.motion->cluster;
      for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
        if (est_.landmark_cluster[i] != label || !Adjusted(i)) continue;
        for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
          const int f = obs.frame - est_.range.begin;
          const int k = cs.frame_index[f];
          if (k < 0) continue;
          if (solve.AddCoupledObservation(obs, &cam_from_world_[f], &cs.world_from_cluster[k],
                                          points_[i].data()))
            ++counts[&cs.world_from_cluster[k]];
        }
      }
      HoldWeakPoses(cs.world_from_cluster, counts, options_.min_observations_per_pose, &solve);
    }
    HoldWeakPoses(cam_from_world_, counts, options_.min_observations_per_pose, &solve);
    HoldFixedCameras(&solve);
    if (!cam_from_world_.empty()) solve.HoldConstant(&cam_from_world_[0]);
    solve.Run(summary);
    for (ClusterState& cs : clusters_)
      for (size_t k = 0; k < cs.motion->frames.size(); ++k) {
        const int f = cs.motion->frames[k] - est_.range.begin;
        cs.cam_from_cluster[k] =
            PoseBlock::From(cam_from_world_[f].ToPose() * cs.world_from_cluster[k].ToPose());
      }
  }

  /// Step (3): P^q_t = P^c_t T^{cq}_t, and the refined values back into the estimate.
  void WriteBack() {
    // Fixed poses are not written back: the quaternion round trip would perturb them in the
    // last bits, and the caller relies on them being exactly the map's.
    for (size_t f = 0; f < cam_from_world_.size() && !clusters_only_; ++f)
      if (!fixed_cameras_[f]) est_.world_from_cam[f] = cam_from_world_[f].ToPose().inverse();
    for (size_t i = 0; i < points_.size(); ++i)
      if (Usable(static_cast<int>(i)))
        est_.landmark_in_cluster[i] = Eigen::Vector3d(points_[i][0], points_[i][1], points_[i][2]);
    for (ClusterState& cs : clusters_) {
      ClusterMotion& m = *cs.motion;
      m.world_from_cluster.resize(m.frames.size());
      for (size_t k = 0; k < m.frames.size(); ++k) {
        m.cam_from_cluster[k] = cs.cam_from_cluster[k].ToPose();
        m.world_from_cluster[k] =
            est_.world_from_cam[m.frames[k] - est_.range.begin] * m.cam_from_cluster[k];
      }
    }
    for (size_t i = 0; i < points_.size(); ++i)
      if (held_out_[i] && Usable(static_cast<int>(i)) && !(clusters_only_ && est_.landmark_cluster[i] == 0))
        PlaceHeldOut(static_cast<int>(i));
  }

  /// Mean of the landmark's back-projections mapped into its cluster's frame by the refined
  /// poses; unchanged when none back-projects.
  void PlaceHeldOut(int landmark) {
    const int label = est_.landmark_cluster[landmark];
    const ClusterState* cs = nullptr;
    if (label > 0) {
      auto it = cluster_of_label_.find(label);
      if (it == cluster_of_label_.end()) return;
      cs = &clusters_[it->second];
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (const StereoObservation& obs : table_.ObservationsOf(landmark, est_.range)) {
      const int f = obs.frame - est_.range.begin;
      Pose cluster_from_cam;
      if (cs) {
        const int k = cs->frame_index[f];
        if (k < 0) continue;
        cluster_from_cam = cs->motion->cam_from_cluster[k].inverse();
      } else {
        cluster_from_cam = est_.world_from_cam[f];
      }
      Eigen::Vector3d p;
      if (!camera_.BackProject<double>(obs.x, &p)) continue;
      sum += cluster_from_cam * p;
      ++count;
    }
    if (count > 0) est_.landmark_in_cluster[landmark] = sum / count;
  }

  const TrackletTable& table_;
  const StereoCamera& camera_;
  const BundleAdjustmentOptions& options_;
  MotionEstimate& est_;
  const bool clusters_only_;  // AdjustClusterMotions: step (1) alone, the rest as given
  std::vector<PoseBlock> cam_from_world_;
  std::vector<std::array<double, 3>> points_;
  std::vector<ClusterState> clusters_;
  std::map<int, int> cluster_of_label_;
  std::vector<bool> held_out_;  // [landmark id]
  std::vector<bool> fixed_cameras_;  // [frame - range.begin]
  bool any_fixed_camera_ = false;
};

}  // namespace

namespace {

// A solve that failed or whose cost grew must not feed the next step: the estimate goes back
// to what was given, marked, and the log says so.
void FallBackWhenUnusable(const BundleAdjustmentSummary& summary, const MotionEstimate& given,
                          const char* what, MotionEstimate* estimate) {
  if (summary.usable) return;
  *estimate = given;
  estimate->adjustment_failed = true;
  GetLogger("backend")->warn("{} over frames {}..{} not usable ({}): the estimate it was given "
                             "is kept and marked", what, estimate->range.begin,
                             estimate->range.end - 1, summary.why);
}

}  // namespace

BundleAdjustmentSummary AdjustBundle(const TrackletTable& table, const StereoCamera& camera,
                                     const BundleAdjustmentOptions& options,
                                     MotionEstimate* estimate, const std::vector<bool>* held_out,
                                     const std::vector<bool>* fixed_cameras) {
  CSLAM_CHECK(static_cast<int>(estimate->world_from_cam.size()) == estimate->range.size(),
              "AdjustBundle: world_from_cam must have one pose per frame of the range");
  CSLAM_CHECK(estimate->landmark_cluster.size() == estimate->landmark_in_cluster.size(),
              "AdjustBundle: landmark_cluster and landmark_in_cluster must be parallel");
  const double initial = EvaluateChi2(table, camera, estimate);
  const MotionEstimate given = *estimate;
  BundleAdjustmentSummary summary =
      Adjuster(table, camera, options, estimate, held_out, fixed_cameras).Run();
  FallBackWhenUnusable(summary, given, "bundle adjustment", estimate);
  summary.initial_chi2 = initial;
  summary.final_chi2 = EvaluateChi2(table, camera, estimate);
  summary.num_residuals = estimate->num_residuals;
  return summary;
}

BundleAdjustmentSummary AdjustClusterMotions(const TrackletTable& table, const StereoCamera& camera,
                                             const BundleAdjustmentOptions& options,
                                             MotionEstimate* estimate) {
  CSLAM_CHECK(static_cast<int>(estimate->world_from_cam.size()) == estimate->range.size(),
              "AdjustClusterMotions: world_from_cam must have one pose per frame of the range");
  const double initial = EvaluateChi2(table, camera, estimate);
  const MotionEstimate given = *estimate;
  BundleAdjustmentSummary summary =
      Adjuster(table, camera, options, estimate, nullptr, nullptr, true).Run();
  FallBackWhenUnusable(summary, given, "cluster-motion adjustment", estimate);
  summary.initial_chi2 = initial;
  summary.final_chi2 = EvaluateChi2(table, camera, estimate);
  summary.num_residuals = estimate->num_residuals;
  return summary;
}

double EvaluateChi2(const TrackletTable& table, const StereoCamera& camera,
                    MotionEstimate* estimate, std::vector<double>* per_landmark_mean) {
  const FrameRange range = estimate->range;
  std::map<int, const ClusterMotion*> by_label;
  for (const ClusterMotion& m : estimate->clusters) by_label[m.cluster] = &m;
  const int n = static_cast<int>(estimate->landmark_cluster.size());
  if (per_landmark_mean) per_landmark_mean->assign(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<Pose> cam_from_world;
  for (const Pose& p : estimate->world_from_cam) cam_from_world.push_back(p.inverse());
  double chi2 = 0.0;
  int count = 0;
  for (int i = 0; i < n && i < table.num_landmarks(); ++i) {
    const int label = estimate->landmark_cluster[i];
    const Eigen::Vector3d& point = estimate->landmark_in_cluster[i];
    if (label < 0 || !point.allFinite()) continue;
    const ClusterMotion* motion = nullptr;
    if (label > 0) {
      auto it = by_label.find(label);
      if (it == by_label.end()) continue;
      motion = it->second;
    }
    double sum = 0.0;
    int num = 0;
    for (const StereoObservation& obs : table.ObservationsOf(i, range)) {
      Eigen::Vector3d p_in_cam;
      if (motion) {
        auto f = std::lower_bound(motion->frames.begin(), motion->frames.end(), obs.frame);
        if (f == motion->frames.end() || *f != obs.frame) continue;
        p_in_cam = motion->cam_from_cluster[f - motion->frames.begin()] * point;
      } else {
        p_in_cam = cam_from_world[obs.frame - range.begin] * point;
      }
      if (p_in_cam.z() == 0.0) continue;
      Eigen::Vector3d predicted;
      camera.Project(p_in_cam, &predicted);
      const Eigen::Vector3d e = obs.x - predicted;
      Eigen::Matrix3d info;
      double det;
      const double m2 = InvertSpd3(obs.cov, &info, &det) ? e.dot(info * e) : e.dot(obs.cov.ldlt().solve(e));
      sum += m2;
      ++num;
    }
    chi2 += sum;
    count += num;
    if (per_landmark_mean && num > 0) (*per_landmark_mean)[i] = sum / num;
  }
  estimate->chi2 = chi2;
  estimate->num_residuals = count;
  return chi2;
}

}  // namespace cslam
