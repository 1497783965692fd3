#include "backend/bundle_adjustment_options.h"

#include <string>

#include "core/errors.h"

namespace cslam {

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
  reader.Read("coupling", kBaCouplingNames, &coupling);
  reader.Read("robust_kernel", kRobustKernelNames, &robust_kernel);
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
  reader.Read("sparse_solver", kSparseSolverNames, &sparse_solver);
  reader.Read("sparse_library", kSparseLibraryNames, &sparse_library);
}
}  // namespace cslam
