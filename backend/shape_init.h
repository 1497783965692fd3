#pragma once
// Noise-aware cluster shape initialisation (clusterslam_spec.md §5, paper Eq. 3 and 4): walk
// the frames in which a cluster is visible, register each frame to the cluster's model with a
// covariance-weighted Gauss–Newton ICP (known correspondences), then integrate the frame's
// back-projected points into per-landmark Gaussian mixtures.
//
// Frames: the cluster frame q is the left camera frame at the cluster's first sight (the first
// frame of the range where at least `min_points` of its landmarks are observed with positive
// disparity). cluster_from_cam = T^{qc}_t maps points of camera frame t into the cluster frame.
//
// Frames where fewer than `min_points` modelled landmarks are observed cannot be registered:
// they take the pose of the previous registered frame (frames before first sight take the
// first sight's pose, the identity) and integrate nothing; they are flagged in `registered`.
// A landmark observed only in such frames is placed from its first observation with that
// carried pose, so that every landmark of the cluster has a position for bundle adjustment.
#include <Eigen/Core>
#include <span>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Parameters of the shape initialisation.
struct ShapeInitOptions {
  /// Gaussian-mixture components kept per landmark [paper: 3].
  int max_mixture_components = 3;
  /// Gauss–Newton iterations of one frame-to-model registration.
  int max_gauss_newton_iterations = 15;
  /// Stop Gauss–Newton when the update is below this (rad and m, max-norm).
  double gauss_newton_step_tolerance = 1e-9;
  /// Huber threshold on the Mahalanobis distance of a registration residual, in sigmas
  /// [ours: robust weight against bad tracks; 3 ≈ sqrt of the 0.99 χ²(3) quantile / 1.1].
  double huber_threshold_sigma = 3.0;
  /// Registered points needed to estimate a frame's pose (3 non-collinear fix a rigid pose).
  int min_points = 3;
  /// [ours] Evaluate an observation's 3-D covariance J_f Σ J_fᵀ at the model's predicted
  /// keypoint rather than at the noisy measurement (once the landmark is modelled). At the
  /// measurement the covariance is correlated with the noise, and the 1/|Σ| weights then
  /// prefer points measured too close, biasing shapes and making trajectories drift.
  bool covariance_at_model = true;
  /// [ours] Gate of Eq. 4 on the innovation χ² (3 dof) of a new observation against the
  /// landmark's model: d² = (p − X̂)ᵀ (Σ_new + Σ_X̂)⁻¹ (p − X̂), Σ_X̂ = (Σ_g Σ_g⁻¹)⁻¹ over the kept
  /// components; a farther observation is not integrated (the model keeps its mean). Why: with
  /// matrix weights, Eq. 4 of observations that disagree (a point on a moving car in a
  /// cluster that does not move with it — every car point under Full BA) is the intersection
  /// of their depth-elongated ellipsoids, which lies arbitrarily far away; measured on a
  /// generated outdoor sequence, the means ran away and the unweighted SVD start of the
  /// registration followed them, and so did the camera. Default 16.27 = the 0.999 quantile of
  /// χ²(3): a consistent observation is refused once in a thousand. <= 0 disables the gate.
  /// ClusterSLAM runs without it (default 0): its first iteration's all-but-static cluster
  /// holds the cars, and the gate's refusals of their points made that start worse (measured:
  /// a generated outdoor sequence lost its camera with the gate; KITTI raw 0005 and the other
  /// synthetic sequences equal or better without;
  /// docs/experiments/2026-12-01-fusion-gate-baselines-only.md).
  double fusion_gate_chi2 = 0.0;
  /// [ours] A fused mean farther from the camera of the observation just integrated than this
  /// many times that observation's range marks the landmark as not moving with the cluster
  /// (as a fusion-gate refusal does: it is then placed at the mean of its observations). Why:
  /// without the gate, the matrix-weighted Eq. 4 of observations that disagree can run away
  /// along the depth-elongated ellipsoids, and with covariance_at_model a far mean makes every
  /// new observation's Σ larger still, so nothing pulls it back; measured on a generated
  /// outdoor sequence at full length, batch: the means ran far away from their observations,
  /// the registration followed them and the window's camera came out infinite
  /// (docs/experiments/2026-12-02-run-away-fusion-guard.md). A consistent
  /// observation is within its depth noise of the mean (≤ 1.5× its range at 100 m and 1 px).
  /// <= 0 disables it.
  double max_fused_range_ratio = 4.0;
  /// The gate the baselines (Full BA, P. DCS) use in place of fusion_gate_chi2: they fuse
  /// every car point into the static cluster, and without it they diverge (10¹⁶–10³⁵ m).
  /// 16.27 = the 0.999 quantile of χ²(3). <= 0 disables it.
  double baseline_fusion_gate_chi2 = 16.27;
  /// [ours] Register each frame by MSAC (minimal 3-point samples, truncated Mahalanobis cost)
  /// and then Eq. 3 on the hypothesis' inliers only, instead of Eq. 3 on every correspondence.
  /// Why: a cluster that holds landmarks which do not move with it (cars in the first static
  /// cluster, which holds nearly everything) otherwise gets the least-squares compromise
  /// between the motions; near car points are precise and dominate it (measured on a
  /// generated outdoor sequence: the first registered frame is off and many static landmarks
  /// are then refused by the fusion gate). The largest consistent set wins instead.
  /// Off by default: with refit_passes 2 and hold_out_inconsistent_landmarks it recovers the
  /// camera on that sequence, but the short outdoor suite test's clustering accuracy fell
  /// below its threshold [docs/experiments/2026-12-01-robust-shape-initialisation.md].
  /// EstimateMotions applies it, and refit_passes, to the static cluster only.
  bool robust_registration = false;
  /// Squared Mahalanobis distance (3 dof) under which a correspondence supports a hypothesis;
  /// the MSAC cost of a correspondence is min(d², this). Default = the 0.999 quantile of χ²(3).
  double ransac_inlier_chi2 = 16.27;
  /// Upper bound on the minimal samples drawn per frame.
  int ransac_max_samples = 200;
  /// Stop sampling once a better hypothesis is this unlikely to be missed (the usual
  /// RANSAC bound from the best inlier fraction w: samples ≥ log(1 − c) / log(1 − w³)).
  double ransac_confidence = 0.999;
  /// [ours] Passes of the shape initialisation that follow the first: each tests every
  /// landmark's whole track against the previous pass's trajectory (reduced χ² of its mapped
  /// back-projections about their information-weighted mean, the model assignment's cost) and
  /// leaves the landmarks above `refit_chi2` out of the next pass's registration and fusion.
  /// Why: a moving body is often indistinguishable from the cluster over the first frames, so
  /// a frame-by-frame registration, robust or not, starts with a compromise that the later
  /// frames inherit; its whole track is decisive (outdoor seed 1, 200 frames, the first static
  /// cluster: reduced χ² > 10 for 98.5 % of its car points, 4.3 % of its static points).
  /// 0 = one pass (the default; 2 measured, see robust_registration); `consistent` is then
  /// the fusion gate's verdict.
  int refit_passes = 0;
  /// Reduced χ² above which a track is left out of the next pass (and flagged inconsistent).
  double refit_chi2 = 10.0;

  /// Throws ConfigError naming the field that breaks its rule.
  void Check() const;
  /// Reads every field by its snake_case name.
  void Load(OptionsReader& reader);
  bool operator==(const ShapeInitOptions&) const = default;
};

/// Shape and trajectory of one cluster in its own frame.
struct ClusterShape {
  std::vector<int> landmarks;                     ///< ascending landmark ids (input order kept)
  std::vector<Eigen::Vector3d> point_in_cluster;  ///< X̂^{q,i}, parallel to landmarks
  /// Parallel to landmarks: false when the landmark does not move with the cluster — with
  /// refit_passes > 0, its track failed the last pass's track test (refit_chi2); otherwise one
  /// of its observations failed the fusion gate (fusion_gate_chi2). Its point is then the mean
  /// of its mapped observations. refit_passes = 0 and the gate off or point_to_point_icp:
  /// always true.
  std::vector<bool> consistent;
  std::vector<int> frames;                        ///< ascending frames where any landmark is seen
  std::vector<Pose> cluster_from_cam;             ///< T^{qc}_t, parallel to frames
  std::vector<bool> registered;                   ///< false: pose carried from a neighbour frame
  int first_sight = -1;                           ///< frame of the cluster frame; -1 = never
  int num_unregistered = 0;                       ///< frames in `frames` not registered
};

/// Initialises the shape of the cluster made of `landmarks` over `range`. With
/// `point_to_point_icp` the registration is the SVD (Umeyama) solution and the integration a
/// running mean (the Table 4 ablation); otherwise Eq. 3 and 4.
ClusterShape InitializeClusterShape(const TrackletTable& table, const StereoCamera& camera,
                                    FrameRange range, std::span<const int> landmarks,
                                    const ShapeInitOptions& options,
                                    bool point_to_point_icp = false);

/// One correspondence of a frame-to-model registration: the back-projected point in the
/// camera frame with its covariance, and the model's mixture for that landmark.
struct RegistrationPoint {
  Eigen::Vector3d p_in_cam;
  Eigen::Matrix3d cov_in_cam;
  Eigen::Vector3d model_mean;                      ///< X̂_{t-1} in the cluster frame
  std::vector<Eigen::Matrix3d> model_covariances;  ///< Σ_g, cluster frame
};

/// Eq. 3: the cluster_from_cam minimising the min-over-components negative log-likelihood,
/// by Gauss–Newton on SE(3) from `initial` with Huber weights. Exposed for tests.
Pose RegisterNoiseAware(const std::vector<RegistrationPoint>& points, const Pose& initial,
                        const ShapeInitOptions& options);

/// [ours] Robust Eq. 3: MSAC over `starts` and minimal 3-point samples (SVD of the three
/// correspondences), each correspondence scored by min(d², ransac_inlier_chi2) with
/// d² = rᵀ (R Σ_cam Rᵀ + Σ_g)⁻¹ r, Σ_g the model's most precise component and R the rotation of
/// starts[0]; the best hypothesis is refined by Gauss–Newton on that cost's inliers, then by
/// Eq. 3 (RegisterNoiseAware) on the inliers when that lowers Eq. 3's cost there.
/// Deterministic for a `seed`. `inliers` (may be null) receives, parallel to `points`,
/// d² < ransac_inlier_chi2 at the result.
Pose RegisterRobust(const std::vector<RegistrationPoint>& points, std::span<const Pose> starts,
                    const ShapeInitOptions& options, unsigned seed,
                    std::vector<bool>* inliers = nullptr);

}  // namespace cslam
