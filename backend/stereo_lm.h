#pragma once
// A dense-Schur Levenberg–Marquardt solver written for the decoupled bundle adjustment's one
// shape of problem: stereo residuals r = S (x − π(R X + t)) that each touch one pose (7
// doubles: Eigen quaternion x, y, z, w, then t) and one point (3 doubles).
//
// Why not Ceres here [ours, measured]: a warm online window spends most of its time in Ceres'
// DENSE_SCHUR, and Ceres has no template specialisation for 3-row residuals on 6-dof poses, so it
// runs its dynamic-size eliminator and locks a mutex per Schur cell
// (docs/experiments/2026-12-01-native-dense-solver.md). With the block sizes fixed at compile time
// the same step costs a fraction. The step is Ceres' own: LM on the tangent space (rotation
// perturbed on the left), damping by the Jacobian's column scale, Ceres' trust-region update, and
// its function-tolerance test, so the two solvers reach the same minimum.
#include <Eigen/Core>
#include <vector>

#include "backend/bundle_adjustment_options.h"
#include "backend/motion_prior.h"
#include "core/stereo_camera.h"

namespace cslam {

/// One whitened stereo observation of point `point` through pose `pose`.
struct StereoLmResidual {
  int pose = 0;
  int point = 0;
  Eigen::Vector3d x;          ///< measured (uL, vL, uR)
  Eigen::Matrix3d sqrt_info;  ///< S with SᵀS = Σ⁻¹
};

/// A constant-velocity prior (backend/motion_prior.h) on poses `pose[0..2]`.
struct StereoLmPrior {
  int pose[3] = {0, 0, 0};
  MotionPriorTerm term;
};

/// The unknowns, in place: each pose 7 doubles, each point 3; `pose_free[i]` false holds pose i.
/// Priors add ½ρ(‖r‖²) each to the cost (Huber, kMotionPriorHuberChi2) and couple their
/// poses, so a problem with priors always eliminates its points.
struct StereoLmProblem {
  std::vector<double*> poses;
  std::vector<bool> pose_free;
  std::vector<double*> points;
  std::vector<StereoLmResidual> residuals;
  std::vector<StereoLmPrior> priors;
};

/// Stopping and kernel settings (the Ceres solve's equivalents).
struct StereoLmOptions {
  RobustKernel kernel = RobustKernel::kHuber;
  double threshold_chi2 = 7.815;  ///< Huber: quadratic below; DCS: Φ
  int max_iterations = 50;        ///< LM iterations, rejected ones included
  double function_tolerance = 1e-6;
  /// Factor the reduced system by its profile (envelope Cholesky) instead of as a dense
  /// matrix: the same factor up to rounding, and in a sequence's bundle adjustment — each
  /// point seen in a run of nearby frames — the reduced camera system over 200 frames is a
  /// band a few dozen poses wide, so the work drops by the square of that ratio.
  bool profile_cholesky = false;
};

/// What the solve did.
struct StereoLmSummary {
  int iterations = 0;
  int successful = 0;
  double initial_cost = 0.0;  ///< ½ Σ ρ(‖r‖²), as Ceres reports it
  double final_cost = 0.0;
  bool converged = false;
  bool failed = false;  ///< the initial state could not be evaluated
};

/// Minimises ½ Σ ρ(‖r‖²) over the free poses and all points, writing the result in place.
StereoLmSummary SolveStereoLm(const StereoCamera& camera, const StereoLmOptions& options,
                              StereoLmProblem* problem);

}  // namespace cslam
