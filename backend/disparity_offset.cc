#include "backend/disparity_offset.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <memory>

#include "backend/covariance_floor.h"
#include "backend/reprojection_error.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"

namespace cslam {

namespace {

/// cam_from_world as one block of 7 (Eigen quaternion x, y, z, w, then translation), the
/// layout StereoReprojectionWithJacobians differentiates.
struct PoseBlock {
  std::array<double, 7> x{0, 0, 0, 1, 0, 0, 0};
  static PoseBlock From(const Pose& cam_from_world) {
    PoseBlock b;
    const Eigen::Quaterniond q(cam_from_world.linear());
    const Eigen::Vector3d& t = cam_from_world.translation();
    b.x = {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
    return b;
  }
};

using PoseManifold = ceres::ProductManifold<ceres::EigenQuaternionManifold,
                                            ceres::EuclideanManifold<3>>;

Eigen::Matrix3d SqrtInformation(const Eigen::Matrix3d& cov) {
  const Eigen::Matrix3d info = cov.inverse();
  return Eigen::LLT<Eigen::Matrix3d>(info).matrixL().transpose();
}

/// r = S ((uL, vL, uR − δ) − π(R X + t)) = S (x − π) − S e₃ δ.
class OffsetReprojectionCost final : public ceres::SizedCostFunction<3, 7, 3, 1> {
 public:
  OffsetReprojectionCost(const StereoCamera& camera, const Eigen::Vector3d& x,
                         const Eigen::Matrix3d& sqrt_info)
      : camera_(camera), x_(x), sqrt_info_(sqrt_info) {}

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    double* d_pose = jacobians ? jacobians[0] : nullptr;
    double* d_point = jacobians ? jacobians[1] : nullptr;
    double* d_offset = jacobians ? jacobians[2] : nullptr;
    double d_q[12], d_t[9];
    if (!StereoReprojectionWithJacobians(camera_, x_, sqrt_info_, p[0], p[0] + 4, p[1], residuals,
                                         d_pose ? d_q : nullptr, d_pose ? d_t : nullptr, d_point))
      return false;
    const double offset = p[2][0];
    for (int r = 0; r < 3; ++r) residuals[r] -= sqrt_info_(r, 2) * offset;
    if (d_pose)  // row-major 3×7 = [3×4 | 3×3]
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) d_pose[7 * r + c] = d_q[4 * r + c];
        for (int c = 0; c < 3; ++c) d_pose[7 * r + 4 + c] = d_t[3 * r + c];
      }
    if (d_offset)
      for (int r = 0; r < 3; ++r) d_offset[r] = -sqrt_info_(r, 2);
    return true;
  }

 private:
  const StereoCamera& camera_;
  Eigen::Vector3d x_;
  Eigen::Matrix3d sqrt_info_;
};

/// One observation of a static landmark: its pose, its point, the keypoint and its weight.
struct Item {
  int pose = -1;
  int point = -1;
  Eigen::Vector3d x;
  Eigen::Matrix3d sqrt_info;
  bool used = true;
};

/// The unknowns of one estimate (camera poses, static points, δ) and the observations that
/// tie them; Ceres problems are built over the observations still in use.
class OffsetProblem {
 public:
  OffsetProblem(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                const std::vector<Pose>& world_from_cam, const DisparityOffsetOptions& options,
                const std::vector<int>& landmark_cluster)
      : camera_(camera), options_(options) {
    poses_.resize(range.size());
    for (int i = 0; i < range.size(); ++i) poses_[i] = PoseBlock::From(world_from_cam[i].inverse());
    for (int l = 0; l < table.num_landmarks(); ++l) {
      if (options.exclude_moving && l < static_cast<int>(landmark_cluster.size()) &&
          landmark_cluster[l] > 0)
        continue;
      const auto obs = table.ObservationsOf(l, range);
      if (static_cast<int>(obs.size()) < options.min_track_length) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int n = 0;
      for (const StereoObservation& o : obs) {
        Eigen::Vector3d p;
        if (!camera.BackProject<double>(o.x, &p)) continue;
        sum += world_from_cam[o.frame - range.begin] * p;
        ++n;
      }
      if (n == 0) continue;
      const Eigen::Vector3d point = sum / n;
      const int index = static_cast<int>(points_.size());
      points_.push_back({point.x(), point.y(), point.z()});
      for (const StereoObservation& o : obs)
        items_.push_back({o.frame - range.begin, index, o.x,
                          SqrtInformation(FloorPixelCovariance(o.cov, options.min_pixel_sigma))});
    }
    Prune();
  }

  /// The same unknowns and observations (not the Ceres problem, which is rebuilt).
  OffsetProblem(const OffsetProblem& o)
      : camera_(o.camera_), options_(o.options_), poses_(o.poses_), points_(o.points_),
        items_(o.items_), offset_(o.offset_), landmarks_(o.landmarks_),
        observations_(o.observations_), frames_(o.frames_) {}
  OffsetProblem& operator=(const OffsetProblem&) = delete;

  /// Stops using the observations whose squared whitened residual at the current state
  /// exceeds `chi2` (and those behind their camera), then every landmark left with fewer
  /// than min_track_length observations.
  void Reject(double chi2) {
    for (Item& item : items_) {
      if (!item.used) continue;
      Eigen::Vector3d r;
      item.used = Residual(item, r.data()) && r.squaredNorm() <= chi2;
    }
    Prune();
  }

  bool empty() const { return observations_ == 0; }
  int landmarks() const { return landmarks_; }
  int observations() const { return observations_; }
  int frames() const { return frames_; }
  double& offset() { return offset_; }

  /// Levenberg–Marquardt over the points, the poses (unless `hold_poses`) and δ (unless
  /// `hold_offset`), from their current values.
  ceres::Solver::Summary Solve(bool hold_offset, bool hold_poses = false) {
    Build();
    if (hold_offset) problem_->SetParameterBlockConstant(&offset_);
    if (hold_poses)
      for (auto& p : poses_)
        if (problem_->HasParameterBlock(p.x.data())) problem_->SetParameterBlockConstant(p.x.data());
    ceres::Solver::Options so;
    so.max_num_iterations = options_.max_iterations;
    so.function_tolerance = 1e-9;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    so.linear_solver_type = ceres::DENSE_SCHUR;
    // Points first (eliminated), then the poses and δ, which the Schur complement keeps.
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (auto& p : points_)
      if (problem_->HasParameterBlock(p.data())) ordering->AddElementToGroup(p.data(), 0);
    for (auto& p : poses_)
      if (problem_->HasParameterBlock(p.x.data())) ordering->AddElementToGroup(p.x.data(), 1);
    ordering->AddElementToGroup(&offset_, 1);
    so.linear_solver_ordering = ordering;
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem_.get(), &summary);
    return summary;
  }

  /// Variance of δ: the δ entry of the inverse Gauss-Newton Hessian of the robust cost at the
  /// current state, with Ceres' weighting of a robust residual (ρ′ JᵀJ). The points are
  /// eliminated point by point into the dense system of the poses and δ, whose inverse
  /// gives it [ours]: Ceres' sparse-QR covariance was the slow part on
  /// 30 frames of KITTI. NaN when the system is singular.
  double OffsetVariance() const {
    int gauge = -1;
    std::vector<bool> observed(poses_.size(), false);
    for (const Item& item : items_)
      if (item.used) {
        observed[item.pose] = true;
        if (gauge < 0 || item.pose < gauge) gauge = item.pose;
      }
    if (gauge < 0) return NAN;
    // Columns: 6 per observed pose but the gauge's (the tangent space: rotation, translation),
    // then δ.
    std::vector<int> column(poses_.size(), -1);
    int n = 0;
    for (size_t i = 0; i < poses_.size(); ++i)
      if (observed[i] && static_cast<int>(i) != gauge) column[i] = 6 * n++;
    const int d = 6 * n;
    Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(d + 1, d + 1);
    const ceres::EigenQuaternionManifold quaternion;
    const std::unique_ptr<ceres::LossFunction> loss = MakeLoss();

    struct Link {
      int col = -1;                            // -1: the gauge pose
      Eigen::Matrix<double, 3, 7> j_pose_d;    // [∂r/∂pose tangent (6) | ∂r/∂δ]
      Eigen::Matrix3d j_point;
      double w = 0;
    };
    std::vector<Link> links;
    for (size_t begin = 0; begin < items_.size();) {
      size_t end = begin;
      while (end < items_.size() && items_[end].point == items_[begin].point) ++end;
      links.clear();
      Eigen::Matrix3d h_pp = Eigen::Matrix3d::Zero();
      for (size_t k = begin; k < end; ++k) {
        const Item& item = items_[k];
        if (!item.used) continue;
        const PoseBlock& pose = poses_[item.pose];
        Eigen::Vector3d r;
        Eigen::Matrix<double, 3, 4, Eigen::RowMajor> d_q;
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> d_t, d_point;
        if (!StereoReprojectionWithJacobians(camera_, item.x, item.sqrt_info, pose.x.data(),
                                             pose.x.data() + 4, points_[item.point].data(),
                                             r.data(), d_q.data(), d_t.data(), d_point.data()))
          continue;
        r -= item.sqrt_info.col(2) * offset_;
        double rho[3];
        loss->Evaluate(r.squaredNorm(), rho);
        Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
        quaternion.PlusJacobian(pose.x.data(), plus.data());
        Link link;
        link.col = column[item.pose];
        link.j_pose_d << d_q * plus, d_t, -item.sqrt_info.col(2);
        link.j_point = d_point;
        link.w = rho[1];
        h_pp += link.w * link.j_point.transpose() * link.j_point;
        links.push_back(link);
      }
      begin = end;
      if (links.empty()) continue;
      const Eigen::Matrix3d h_inv = h_pp.inverse();
      if (!h_inv.allFinite()) return NAN;
      // Per link the 7 columns (pose, δ) and their coupling to the point, B = w J_ptᵀ J_c.
      std::vector<Eigen::Matrix<double, 3, 7>> b(links.size());
      for (size_t i = 0; i < links.size(); ++i)
        b[i] = links[i].w * links[i].j_point.transpose() * links[i].j_pose_d;
      // Scatters a 7×7 block of (pose i tangent, δ) × (pose j tangent, δ); the gauge pose
      // (column −1) has no rows.
      auto add = [&](int ci, int cj, const Eigen::Matrix<double, 7, 7>& block) {
        const int at[2][2] = {{ci, d}, {cj, d}};  // [row/col][pose/δ]
        const int size[2] = {6, 1};
        for (int a = 0; a < 2; ++a)
          for (int c = 0; c < 2; ++c)
            if (at[0][a] >= 0 && at[1][c] >= 0)
              reduced.block(at[0][a], at[1][c], size[a], size[c]) +=
                  block.block(6 * a, 6 * c, size[a], size[c]);
      };
      for (size_t i = 0; i < links.size(); ++i) {
        const Eigen::Matrix<double, 7, 7> own =
            links[i].w * links[i].j_pose_d.transpose() * links[i].j_pose_d;
        add(links[i].col, links[i].col, own);
        for (size_t j = 0; j < links.size(); ++j)
          add(links[i].col, links[j].col, -(b[i].transpose() * h_inv * b[j]));
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(reduced);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return NAN;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(d + 1);
    e(d) = 1.0;
    const double var = ldlt.solve(e)(d);
    return std::isfinite(var) && var > 0 ? var : NAN;
  }

  int NumUnknowns() const { return 3 * landmarks_ + 6 * (frames_ - 1) + 1; }

 private:
  bool Residual(const Item& item, double* r) const {
    const OffsetReprojectionCost cost(camera_, item.x, item.sqrt_info);
    const double* params[] = {poses_[item.pose].x.data(), points_[item.point].data(), &offset_};
    return cost.Evaluate(params, r, nullptr);
  }

  std::unique_ptr<ceres::LossFunction> MakeLoss() const {
    const double scale = std::sqrt(options_.robust_threshold_chi2);
    if (options_.robust_kernel == "huber") return std::make_unique<ceres::HuberLoss>(scale);
    return std::make_unique<ceres::CauchyLoss>(scale);
  }

  // Drops landmarks with too few observations in use and counts what is left.
  void Prune() {
    std::vector<int> per_point(points_.size(), 0);
    for (const Item& item : items_)
      if (item.used) ++per_point[item.point];
    std::vector<bool> frame_used(poses_.size(), false);
    observations_ = landmarks_ = frames_ = 0;
    for (Item& item : items_) {
      if (item.used && per_point[item.point] < options_.min_track_length) item.used = false;
      if (!item.used) continue;
      ++observations_;
      frame_used[item.pose] = true;
    }
    for (int n : per_point) landmarks_ += n >= options_.min_track_length;
    for (bool used : frame_used) frames_ += used;
  }

  void Build() {
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(po);
    loss_ = MakeLoss();
    int gauge = -1;
    for (Item& item : items_) {
      if (!item.used) continue;
      Eigen::Vector3d r;
      if (!Residual(item, r.data())) continue;  // behind the camera at the start
      double* pose = poses_[item.pose].x.data();
      problem_->AddResidualBlock(new OffsetReprojectionCost(camera_, item.x, item.sqrt_info),
                                 loss_.get(), pose, points_[item.point].data(), &offset_);
      if (gauge < 0 || item.pose < gauge) gauge = item.pose;
    }
    for (auto& p : poses_)
      if (problem_->HasParameterBlock(p.x.data())) problem_->SetManifold(p.x.data(), &manifold_);
    // The gauge: the first pose with observations holds the world frame.
    if (gauge >= 0) problem_->SetParameterBlockConstant(poses_[gauge].x.data());
  }

  const StereoCamera& camera_;
  const DisparityOffsetOptions& options_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::LossFunction> loss_;
  PoseManifold manifold_;
  std::vector<PoseBlock> poses_;
  std::vector<std::array<double, 3>> points_;
  std::vector<Item> items_;
  double offset_ = 0.0;
  int landmarks_ = 0, observations_ = 0, frames_ = 0;
};

}  // namespace

void DisparityOffsetOptions::Check() const {
  CheckOption(min_track_length >= 2, "min_track_length", "must be >= 2", min_track_length);
  if (robust_kernel != "huber" && robust_kernel != "cauchy")
    throw ConfigError("robust_kernel", "must be huber or cauchy, got " + robust_kernel);
  CheckOption(robust_threshold_chi2 > 0 && std::isfinite(robust_threshold_chi2),
              "robust_threshold_chi2", "must be finite and > 0", robust_threshold_chi2);
  CheckOption(min_pixel_sigma >= 0 && std::isfinite(min_pixel_sigma), "min_pixel_sigma",
              "must be finite and >= 0 px", min_pixel_sigma);
  CheckOption(max_iterations >= 1, "max_iterations", "must be >= 1", max_iterations);
  CheckOption(outlier_chi2 > 0, "outlier_chi2", "must be > 0", outlier_chi2);
  CheckOption(max_offset_px > 0 && std::isfinite(max_offset_px), "max_offset_px",
              "must be finite and > 0 px", max_offset_px);
}

void DisparityOffsetOptions::Load(OptionsReader& r) {
  r.Read("min_track_length", &min_track_length);
  r.Read("robust_kernel", &robust_kernel);
  r.Read("robust_threshold_chi2", &robust_threshold_chi2);
  r.Read("min_pixel_sigma", &min_pixel_sigma);
  r.Read("max_iterations", &max_iterations);
  r.Read("max_offset_px", &max_offset_px);
  r.Read("outlier_chi2", &outlier_chi2);
  r.Read("exclude_moving", &exclude_moving);
}

double DisparityOffset::Significance() const {
  if (!usable || !(sigma_px > 0)) return 0.0;
  return std::abs(offset_px) / sigma_px;
}

namespace {

// The stages shared by the estimate and its profile: observations the initial motion does not
// explain left out, δ and the structure adjusted on the rest, then the observations that
// solve could not explain left out too. The problem comes back in that state.
void AdjustAndReject(OffsetProblem* problem, const DisparityOffsetOptions& options,
                     int* iterations) {
  // Points that do not follow the initial camera motion at all (moving ones, mismatches)
  // first: left in, they drift for tens of iterations before the kernel has silenced them.
  // Each point is placed first, the motion and δ held: judged at their mean back-projections,
  // the far points — the ones that tell δ — fail the gate most (an earlier probe on this
  // branch, not re-measured).
  *iterations += static_cast<int>(problem->Solve(true, true).iterations.size());
  problem->Reject(options.outlier_chi2);
  *iterations += static_cast<int>(problem->Solve(false).iterations.size());
  problem->Reject(options.outlier_chi2);
}

}  // namespace

DisparityOffset EstimateDisparityOffset(const TrackletTable& table, const StereoCamera& camera,
                                        FrameRange range, const std::vector<Pose>& world_from_cam,
                                        const DisparityOffsetOptions& options,
                                        const std::vector<int>& landmark_cluster) {
  const Timer timer;
  DisparityOffset out;
  CSLAM_CHECK(static_cast<int>(world_from_cam.size()) == range.size(),
              "the disparity offset needs a camera pose per frame of its range");
  OffsetProblem problem(table, camera, range, world_from_cam, options, landmark_cluster);
  if (problem.empty() || problem.frames() < 2) {
    out.reason = "fewer than two frames with static landmarks";
    return out;
  }
  AdjustAndReject(&problem, options, &out.iterations);
  const int first_iterations = out.iterations;
  out.landmarks = problem.landmarks();
  out.observations = problem.observations();
  out.frames = problem.frames();
  if (problem.empty() || out.frames < 2) {
    out.reason = "fewer than two frames with consistent static landmarks";
    return out;
  }
  const ceres::Solver::Summary free = problem.Solve(false);
  out.iterations += static_cast<int>(free.iterations.size());
  GetLogger("backend")->debug("disparity offset final solve: {}", free.BriefReport());
  out.offset_px = problem.offset();
  const int dof = 3 * out.observations - problem.NumUnknowns();
  out.reduced_chi2 = dof > 0 ? 2.0 * free.final_cost / dof : NAN;
  if (free.termination_type == ceres::FAILURE || !std::isfinite(out.offset_px)) {
    out.reason = "the solve failed: " + free.message;
    return out;
  }
  const Timer covariance_timer;
  const double var = problem.OffsetVariance();
  const double covariance_s = covariance_timer.ElapsedS();
  if (!(var > 0)) {
    out.reason = "δ is not observable here (singular Hessian)";
    return out;
  }
  const double inflation = std::isfinite(out.reduced_chi2) ? std::max(1.0, out.reduced_chi2) : 1.0;
  out.sigma_px = std::sqrt(var * inflation);
  if (std::abs(out.offset_px) > options.max_offset_px) {
    out.reason = "|δ| beyond max_offset_px";
    return out;
  }
  out.usable = true;
  GetLogger("backend")->debug(
      "disparity offset over frames {}..{}: {:+.4f} ± {:.4f} px ({} landmarks, {} observations, "
      "reduced χ² {:.3f}, LM iterations {} + {}, {:.2f} s, covariance {:.2f} s)",
      range.begin, range.end - 1, out.offset_px, out.sigma_px, out.landmarks, out.observations,
      out.reduced_chi2, first_iterations, free.iterations.size(), timer.ElapsedS(), covariance_s);
  return out;
}

std::vector<double> ProfileDisparityOffset(const TrackletTable& table, const StereoCamera& camera,
                                           FrameRange range, const std::vector<Pose>& world_from_cam,
                                           const DisparityOffsetOptions& options,
                                           const std::vector<double>& offsets,
                                           const std::vector<int>& landmark_cluster) {
  std::vector<double> costs(offsets.size(), NAN);
  if (static_cast<int>(world_from_cam.size()) != range.size()) return costs;
  OffsetProblem base(table, camera, range, world_from_cam, options, landmark_cluster);
  if (base.empty()) return costs;
  int iterations = 0;
  AdjustAndReject(&base, options, &iterations);
  if (base.empty()) return costs;
  for (size_t k = 0; k < offsets.size(); ++k) {
    // Every point of the curve starts from the same state and observations.
    OffsetProblem problem = base;
    problem.offset() = offsets[k];
    costs[k] = problem.Solve(true).final_cost;
  }
  return costs;
}

TrackletTable CorrectDisparities(const TrackletTable& table, double offset_px) {
  TrackletTable out;
  for (int f = table.first_held_frame(); f < table.num_frames(); ++f)
    for (const ObservationRef& ref : table.ObservationsAt(f)) {
      const StereoObservation& o = table.Get(ref);
      out.Add(o.landmark, o.frame, Eigen::Vector3d(o.x(0), o.x(1), o.x(2) - offset_px), o.cov);
    }
  while (out.num_landmarks() < table.num_landmarks()) out.NewLandmark();
  return out;
}

}  // namespace cslam
