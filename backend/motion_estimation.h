#pragma once
// Given a labelling of landmarks into rigid clusters, estimate every cluster's shape and
// trajectory and the camera's (clusterslam_spec.md §5 shape initialisation + §6 decoupled BA).
// Frames: world = the camera frame at range.begin (the static cluster's frame, P⁰ ≡ I).
#include <Eigen/Core>
#include <vector>

#include "backend/bundle_adjustment_options.h"
#include "backend/shape_init.h"
#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Trajectory of one moving cluster over the frames where it is observed.
struct ClusterMotion {
  int cluster = -1;                       ///< label (>= 1)
  std::vector<int> frames;                ///< ascending absolute frame indices
  std::vector<Pose> cam_from_cluster;     ///< T^{cq}_t, parallel to frames
  std::vector<Pose> world_from_cluster;   ///< P^q_t = P^c_t T^{cq}_t, parallel to frames
};

/// Output of EstimateMotions and of every backend method.
struct MotionEstimate {
  FrameRange range;
  std::vector<Pose> world_from_cam;                  ///< [frame - range.begin]
  std::vector<int> landmark_cluster;                 ///< [landmark id]: -1 unused, 0 static, >0 moving
  std::vector<Eigen::Vector3d> landmark_in_cluster;  ///< [landmark id]; NaN where unused
  std::vector<ClusterMotion> clusters;               ///< moving clusters, ascending label
  double chi2 = 0.0;         ///< Σ squared Mahalanobis reprojection error, no robust kernel
  int num_residuals = 0;     ///< observations in chi2
  /// A bundle adjustment of this estimate was not usable: it holds what that adjustment was
  /// given (the shape initialisation or the previous estimate) instead.
  bool adjustment_failed = false;

  /// The moving cluster with `label`, or nullptr.
  const ClusterMotion* FindCluster(int label) const;
};

/// Options of EstimateMotions (spec §5, §6).
struct MotionEstimationOptions {
  ShapeInitOptions shape_init;                ///< section "shape_init"
  BundleAdjustmentOptions bundle_adjustment;  ///< section "bundle_adjustment"
  /// Ablation [paper Table 4]: SVD point-to-point ICP and mean integration instead of the
  /// noise-aware registration and integration.
  bool point_to_point_icp = false;
  /// false: return the shape initialisation without bundle adjustment (ablation, tests).
  bool run_bundle_adjustment = true;
  /// [ours] Landmarks the shape initialisation found inconsistent with their cluster (an
  /// observation failed the fusion gate, ShapeInitOptions::fusion_gate_chi2) stay out of the
  /// bundle adjustment and are re-placed at the mean of their mapped observations after it.
  /// Why: a car point labelled static is explained best by a point at infinity along its ray;
  /// in the adjustment such points keep drifting outwards and the solve does not converge
  /// within its iterations. Static cluster only. Off by default [measured]: with the fusion
  /// gate's verdict it found fewer objects; with shape_init.robust_registration and
  /// refit_passes 2 it recovers the camera on a generated outdoor sequence where the cold loop
  /// loses it, but lowers a short outdoor run's clustering accuracy below the suite test's
  /// threshold (docs/experiments/2026-12-01-batch-speed.md,
  /// docs/experiments/2026-12-01-robust-shape-initialisation.md).
  bool hold_out_inconsistent_landmarks = false;

  /// Throws ConfigError naming the field that breaks its rule.
  void Check() const;
  /// Reads every field by its snake_case name; nested options from their sections.
  void Load(OptionsReader& reader);
  bool operator==(const MotionEstimationOptions&) const = default;
};

/// [ours] The moving clusters of the latest EstimateMotions call, for reuse by the next one.
/// With the decoupled adjustment a moving cluster's shape and trajectory T^{cq}_t depend only
/// on its landmarks, the range and the options, so a cluster given exactly the same landmarks
/// again is copied instead of re-estimated — the same numbers, since the computation would
/// repeat. The outer loop's re-labelling leaves many clusters untouched (docs/backend.md).
struct MovingClusterCache {
  struct Entry {
    std::vector<int> landmarks;           ///< the landmarks labelled with it, ascending
    ClusterMotion motion;                 ///< world_from_cluster left empty (camera-dependent)
    std::vector<Eigen::Vector3d> points;  ///< landmark_in_cluster, parallel; NaN = unused
  };
  FrameRange range;
  MotionEstimationOptions options;
  std::vector<Entry> entries;
  int reused = 0;  ///< clusters copied by the latest call
};

/// Shapes and trajectories of every cluster of `landmark_cluster` ([landmark id]: -1 unused,
/// 0 static, > 0 moving; shorter than the table → missing ids unused) over `range`: noise-aware
/// shape initialisation per cluster, then bundle adjustment. World = the camera frame at
/// range.begin. Landmarks without an observation in the range, or without a position (never a
/// positive disparity), come back with label -1. Without any static landmark the camera stays
/// at the identity (its motion is unobservable) and a warning is logged.
///
/// `warm_start` (may be null) [ours]: a previous estimate over the same range. The static
/// cluster then starts from its camera poses and static landmark positions (new static
/// landmarks at the mean of their back-projections through those poses) instead of the
/// frame-to-frame shape initialisation: the outer loop's labellings differ by a few
/// landmarks between iterations, and the static adjustment — most of the time — converges
/// in a few iterations from there instead of removing the initialisation's drift again.
///
/// `cache` (may be null) [ours]: moving clusters of the previous call are reused when the
/// landmark set, range and options are the same and the coupling is decoupled (the result is
/// then identical to re-estimating them); afterwards it holds this call's moving clusters.
///
/// `fixed_cameras` (may be null; [frame - range.begin]) [ours]: camera poses the bundle
/// adjustment holds at the warm start's poses (AdjustBundle) — an online window's frames the
/// map already has. Ignored without a usable `warm_start` or without static landmarks.
MotionEstimate EstimateMotions(const TrackletTable& table, const StereoCamera& camera,
                               FrameRange range, const std::vector<int>& landmark_cluster,
                               const MotionEstimationOptions& options,
                               const MotionEstimate* warm_start = nullptr,
                               MovingClusterCache* cache = nullptr,
                               const std::vector<bool>* fixed_cameras = nullptr);

}  // namespace cslam
