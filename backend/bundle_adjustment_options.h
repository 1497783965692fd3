#pragma once
// Options of the multi-body bundle adjustment (backend/bundle_adjustment.h), apart from it so
// that MotionEstimationOptions can hold them without a circular include.
#include <memory>
#include <string>

#include "core/enum_names.h"
#include "core/options_reader.h"
#include "core/task_runner.h"

namespace cslam {

/// Robust kernel ρ applied to each squared whitened residual.
enum class RobustKernel { kNone, kHuber, kDcs };
/// How cluster and camera unknowns are split between solves (paper Table 5).
enum class BaCoupling { kDecoupled, kSemiCoupled, kFullyCoupled };

/// The linear solver of large solves: Ceres SPARSE_NORMAL_CHOLESKY, SPARSE_SCHUR, or
/// ITERATIVE_SCHUR (conjugate gradients on the reduced camera system, SCHUR_JACOBI
/// preconditioner).
enum class SparseSolver { kNormalCholesky, kSchur, kIterativeSchur };
/// The sparse factorisation library of the direct sparse solvers.
enum class SparseLibrary { kSuiteSparse, kEigen };

/// The spelling of each enum in configs (core/enum_names.h).
inline constexpr EnumName<SparseSolver> kSparseSolverNames[] = {
    {SparseSolver::kNormalCholesky, "normal_cholesky"},
    {SparseSolver::kSchur, "schur"},
    {SparseSolver::kIterativeSchur, "iterative_schur"}};
inline constexpr EnumName<SparseLibrary> kSparseLibraryNames[] = {
    {SparseLibrary::kSuiteSparse, "suite_sparse"}, {SparseLibrary::kEigen, "eigen"}};
inline constexpr EnumName<RobustKernel> kRobustKernelNames[] = {
    {RobustKernel::kNone, "none"}, {RobustKernel::kHuber, "huber"}, {RobustKernel::kDcs, "dcs"}};
inline constexpr EnumName<BaCoupling> kBaCouplingNames[] = {
    {BaCoupling::kDecoupled, "decoupled"},
    {BaCoupling::kSemiCoupled, "semi_coupled"},
    {BaCoupling::kFullyCoupled, "fully_coupled"}};

/// Parameters of the bundle adjustment.
struct BundleAdjustmentOptions {
  /// Split of the unknowns [paper: decoupled is the default].
  BaCoupling coupling = BaCoupling::kDecoupled;
  /// Robust kernel [ours: Huber — convex, so it cannot lock onto a wrong basin when the
  /// initialisation is poor, yet caps the pull of bad tracks; the paper's DCS is an option].
  RobustKernel robust_kernel = RobustKernel::kHuber;
  /// Kernel threshold on the squared whitened residual (χ² units, 3 dof). Huber: quadratic
  /// below it; DCS: Φ. Default 7.815 = the 0.95 quantile of χ²(3).
  double robust_threshold_chi2 = 7.815;
  /// Levenberg–Marquardt iterations per solve [paper ablation: 20].
  int max_iterations = 50;
  /// LM iterations of the moving clusters' solves (the decoupled scheme's step 1, and the
  /// semi-coupled one's); < 0: max_iterations.
  int moving_max_iterations = -1;
  /// Relative cost decrease below which a solve stops.
  double function_tolerance = 1e-6;
  /// Threads Ceres may use inside one solve (1 on the shared machine).
  int num_threads = 1;
  /// Observations a pose needs to be optimised; fewer → held at its initial value.
  int min_observations_per_pose = 3;
  /// Poses (frames × bodies) from which a solve uses the sparse solver below instead of
  /// DENSE_SCHUR. Measured (docs/experiments/2026-11-23-backend-speed.md): 0 takes fewer
  /// instructions on a short outdoor estimation, but CHOLMOD's BLAS threads then spin on a
  /// shared machine and online runs got slower in wall and system time, so 60 stays.
  int sparse_schur_min_poses = 60;
  /// [ours, measured] sparse normal Cholesky: with tracks tens of frames long, Ceres' sparse
  /// Schur spends more time building the reduced camera system's block structure and
  /// locking its cells than solving (slower on synthetic indoor and outdoor chunks, same
  /// result; docs/experiments/2026-11-23-backend-speed.md).
  SparseSolver sparse_solver = SparseSolver::kNormalCholesky;
  /// Factorisation library of normal_cholesky / schur [SuiteSparse's CHOLMOD; eigen = Eigen's
  /// simplicial LDLᵀ, no BLAS].
  SparseLibrary sparse_library = SparseLibrary::kSuiteSparse;
  /// Sparse normal Cholesky: constrain the elimination order to all points before all poses
  /// (the behaviour before 2026-11-23). Off [ours, measured]: the minimum-degree ordering picks
  /// the cheaper side itself — much faster on small moving clusters seen in many frames, same
  /// solution (docs/experiments/2026-11-23-backend-speed.md).
  bool points_first_sparse_ordering = false;
  /// DENSE_SCHUR eliminates the poses instead of the points when the points' reduced system
  /// (3 per free point) is smaller than the poses' (6 per free pose) and every residual
  /// touches one pose (the decoupled solves: the poses are then independent of one another,
  /// as Schur elimination needs) [ours, measured]. A warm window's moving clusters — a few
  /// landmarks in 25–30 frames — then factor a 3·points square instead of 6·frames. Same
  /// normal equations, same step.
  bool dense_schur_smaller_side = true;
  /// Closed-form Jacobians of the decoupled residual (backend/reprojection_error.h) instead of
  /// Ceres' automatic differentiation [ours, measured: same values to rounding, fewer
  /// instructions]. The coupled modes' two-pose residual stays automatic.
  bool analytic_jacobians = true;
  /// Solves that would use DENSE_SCHUR and whose residuals each touch one pose (the decoupled
  /// ones) run on backend/stereo_lm.h, a Levenberg–Marquardt with the stereo block sizes fixed
  /// at compile time, instead of Ceres [ours, measured: same minimum, a fraction of the time;
  /// docs/experiments/2026-12-01-native-dense-solver.md].
  bool native_dense_solver = true;
  /// Solves with at least `sparse_schur_min_poses` poses whose residuals each touch one pose
  /// (the decoupled ones) also run on backend/stereo_lm.h, with the reduced system factored
  /// by its profile (envelope Cholesky), instead of Ceres' sparse solver [ours, measured:
  /// less CPU on outdoor batch runs, but the clustering loop then ends on other labellings,
  /// some worse — so off by default; docs/experiments/2026-12-02-native-profile-solver.md].
  bool native_sparse_solver = false;
  /// [ours; ORB-SLAM's close/far split] Static landmarks farther from a camera than this many
  /// stereo baselines (at their current estimate) have the variance of that observation's
  /// right column raised by far_disparity_sigma_px², so the camera's translation takes its scale
  /// from near points and far ones constrain it like monocular points. Why: a rectified pair
  /// carries a constant disparity offset its calibration does not state (KITTI clip_a:
  /// ~0.13 px, docs/frontend.md), which stretches a point's depth by offset / disparity — 1 %
  /// at 13 px. 0 = off (the default: exact calibrations, as in rendered and generated
  /// sequences, lose scale information by it); configs/kitti_*.yaml set 35, ORB-SLAM's
  /// ThDepth for KITTI. Moving clusters keep every disparity: their depth is all they have.
  double far_depth_baselines = 0.0;
  /// Standard deviation added to a far static observation's right column, px, > 0.
  double far_disparity_sigma_px = 10.0;
  /// [ours, beyond the paper] Constant-velocity prior on each moving cluster's poses in three
  /// consecutive frames (backend/motion_prior.h), in the moving-cluster solve: standard
  /// deviations of the body centre's second difference (m per frame²) and of the change of its
  /// per-frame rotation (rad). Both 0 = off; both > 0 = on.
  double motion_prior_sigma_m = 0.0;
  double motion_prior_sigma_rad = 0.0;
  /// Not from YAML: runs the decoupled scheme's solves (each moving cluster, the static
  /// world) side by side, and EstimateMotions' shape initialisations; null: one after another.
  /// The result is the same either way. Set by system/ (pipeline option `backend_threads`).
  std::shared_ptr<const TaskRunner> runner;

  /// Throws ConfigError naming the field that breaks its rule.
  void Check() const;
  /// Reads every field by its snake_case name (enums as the strings above).
  void Load(OptionsReader& reader);
  bool operator==(const BundleAdjustmentOptions&) const = default;
};

}  // namespace cslam
