#pragma once
// Multi-body stereo bundle adjustment (clusterslam_spec.md §6, paper Eq. 5). Residuals are
// stereo reprojection errors (uL, vL, uR) whitened by the 3×3 pixel covariance; rotations are
// quaternions on a manifold. Ceres stays in the .cc file.
//
// The state is a MotionEstimate refined in place: world_from_cam, landmark_in_cluster
// (static landmarks in the world frame, moving ones in their cluster's frame) and each moving
// cluster's cam_from_cluster; world_from_cluster is recomposed as P^c_t T^{cq}_t.
// Gauge: the first camera pose of the range is held fixed, and each moving cluster's pose at
// its first well-observed frame is held fixed (a cluster's frame is arbitrary up to SE(3)).
// A pose seen by fewer than `min_observations_per_pose` observations is held at its
// initial value (its carried-forward estimate): it cannot be determined from them.
#include <string>
#include <vector>

#include "backend/bundle_adjustment_options.h"
#include "backend/motion_estimation.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// What a bundle adjustment did.
struct BundleAdjustmentSummary {
  double initial_chi2 = 0.0;  ///< Σ squared Mahalanobis error before, no robust kernel
  double final_chi2 = 0.0;    ///< after
  int num_residuals = 0;      ///< observations counted in the χ² values
  int iterations = 0;         ///< LM iterations summed over the solves
  int num_solves = 0;
  /// false when a solve failed (Ceres FAILURE, a point behind a camera) or ended above its
  /// starting cost; the estimate was then given back unchanged and marked
  /// (MotionEstimate::adjustment_failed).
  bool usable = true;
  std::string why;  ///< the first unusable solve and what happened
};

/// Refines `estimate` in place (see the header comment for the frames and the gauge).
/// Precondition: `estimate` is initialised for `table` over estimate->range (landmark_cluster
/// sized to the table, clusters listing every frame where their landmarks are observed).
/// `held_out` (may be null; [landmark id], shorter = not held): landmarks kept out of every
/// solve — they keep their cluster, and afterwards are placed at the mean of their
/// back-projections through the refined poses of their cluster.
/// `fixed_cameras` (may be null; [frame - range.begin], shorter = free) [ours]: camera poses
/// held at their value in the static and coupled solves, as the gauge frame is — an online
/// window's frames whose poses the map already has (the map keeps its own poses), so only
/// the newest frames' poses and the points are estimated. Static landmarks that only held
/// poses (fixed or the gauge frame) observe are decoupled from every free unknown and stay
/// out of the solve with their position unchanged (leaving them out changes nothing else).
BundleAdjustmentSummary AdjustBundle(const TrackletTable& table, const StereoCamera& camera,
                                     const BundleAdjustmentOptions& options,
                                     MotionEstimate* estimate,
                                     const std::vector<bool>* held_out = nullptr,
                                     const std::vector<bool>* fixed_cameras = nullptr);

/// Step (1) of the decoupled scheme alone: every moving cluster's landmarks and per-frame poses
/// (with options' motion prior, when set), the camera poses and static landmarks as given.
/// ClusterSLAM's last step when the prior is on (backend/clusterslam.h).
BundleAdjustmentSummary AdjustClusterMotions(const TrackletTable& table, const StereoCamera& camera,
                                             const BundleAdjustmentOptions& options,
                                             MotionEstimate* estimate);

/// Σ squared Mahalanobis reprojection error of `estimate` (no robust kernel) over every
/// observation in the range of a landmark with a cluster and a finite position; also writes
/// estimate->chi2 and estimate->num_residuals. When `per_landmark_mean` is given it receives
/// [landmark id] the mean error per observation (NaN for landmarks without one).
double EvaluateChi2(const TrackletTable& table, const StereoCamera& camera,
                    MotionEstimate* estimate, std::vector<double>* per_landmark_mean = nullptr);

}  // namespace cslam
