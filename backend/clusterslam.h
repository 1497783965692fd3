#pragma once
// ClusterSLAM's outer loop, Algorithm 1 (clusterslam_spec.md §2): per-chunk motion distance
// and HAC, consensus, then shape and motion estimation of every cluster, repeated until the
// labelling is stable.
//
// Iterations >= 2 feed the motion distance with refined per-frame positions (RefineTracks in
// point_tracks.h): each landmark's point at frame t is expressed in the CAMERA frame of t —
// the model prediction T^{cq}ₜ X̂^{q,i} (for the static cluster (P^c_t)⁻¹ X̂) plus the
// landmark's windowed mean observation residual. Both landmarks of a pair are therefore in
// the same frame, so dᵢⱼ remains a rigid-motion test across clusters (cluster-frame
// coordinates would make every pair look rigid), and a landmark that does not move with its
// cluster keeps a visible residual drift.
#include <functional>
#include <string>
#include <vector>

#include "backend/backend_result.h"
#include "backend/consensus.h"
#include "backend/hac.h"
#include "backend/motion_distance.h"
#include "backend/model_assignment.h"
#include "backend/motion_estimation.h"
#include "backend/window_prior.h"
#include "core/options_reader.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// The ablations of the paper's Tables 1 and 4.
enum class ClusterSlamAblation {
  kNone,             ///< the full method
  kNoUncertainty,    ///< "w/o U": Euclidean first term of Eq. 1, unweighted mean
  kNoImagePrior,     ///< "w/o I": no image prior in Eq. 1
  kPointToPointIcp,  ///< point-to-point ICP shape initialisation (passed to motion estimation)
};
/// The ablations' one spelling, the same in YAML (`ablation`, `backend.ablation`) and on the
/// command line (`--ablation`).
inline constexpr EnumName<ClusterSlamAblation> kAblationNames[] = {
    {ClusterSlamAblation::kNone, "none"},
    {ClusterSlamAblation::kNoUncertainty, "no-u"},
    {ClusterSlamAblation::kNoImagePrior, "no-i"},
    {ClusterSlamAblation::kPointToPointIcp, "p2p-icp"},
};

/// [ours] The online warm start of RunClusterSlamWindow: how a window uses what the map already
/// knows (backend/window_prior.h). YAML section `backend.window_prior`.
struct WindowPriorOptions {
  bool enabled = true;  ///< false: every window runs the whole loop from scratch (cold start)
  /// Rounds of model assignment + estimation from the prior (the cold loop runs up to
  /// max_iterations full estimations after a pairwise clustering). Measured: a second round
  /// costs CPU and gives the same camera and clustering
  /// (docs/experiments/2026-12-01-online-windows-warm-started.md).
  int max_iterations = 1;
  /// Levenberg–Marquardt iterations of each adjustment (it starts near the answer; the solve
  /// still stops earlier at motion.bundle_adjustment.function_tolerance).
  int ba_iterations = 10;
  /// Relative cost decrease below which a window's adjustment stops; 0 = the cold loop's
  /// motion.bundle_adjustment.function_tolerance (1e-6). [ours, measured] A window starts
  /// near its minimum: on KITTI raw 0005 the static solve's first LM step takes nearly the
  /// whole decrease, and every frame is adjusted again by the next windows. 1e-3 ends it after
  /// fewer steps with the same camera ATE, clustering and objects on KITTI, the odometry clip
  /// and the synthetic runs (docs/experiments/2026-12-02-window-speed.md).
  double function_tolerance = 1e-3;
  /// LM iterations of each moving cluster's solve in a window; 0 = ba_iterations.
  int moving_ba_iterations = 0;
  /// Adjust the prior's first estimate (its labels, the new landmarks left out) before the
  /// model assignment; false: the assignment sees the shape initialisation of the moving
  /// clusters as it is.
  bool adjust_prior = false;
  /// Start the window's moving clusters from the map's (true), or only its static world
  /// (false: landmarks of moving map clusters start unlabelled, and those the static world
  /// does not explain are re-clustered among themselves with Eq. 1 + HAC, as the cold loop's
  /// outliers are). Measured (docs/experiments/2026-12-01-online-windows-warm-started.md): true
  /// keeps the map's fragments of an object apart window after window (indoors it found fewer
  /// objects in more clusters), false finds fewer cars outdoors.
  bool keep_moving_labels = false;
  /// Hold the camera poses the prior has (the map's; it never overwrites them) constant in
  /// the adjustments: only the frames new to the map (and the newest `free_known_frames`
  /// known ones), the moving clusters and the landmarks are estimated, and static landmarks
  /// only held poses see leave the static solve (backend/bundle_adjustment.h). Off by
  /// default [measured, docs/experiments/2026-12-01-faster-warm-windows.md]: it halves a KITTI
  /// window's backend CPU with the same ATE, but a generated outdoor sequence's camera drifts,
  /// less so with some known frames free — a frame's map pose is from the window where it was
  /// newest and least constrained, and holding it chains the new frames to it.
  bool fix_known_poses = false;
  /// With fix_known_poses: the newest this many known poses are adjusted all the same (a
  /// lag; 0 = every known pose held).
  int free_known_frames = 10;
  /// The prior is used only when at least this fraction of the window's frames have a camera
  /// pose in it and at least `min_known_landmarks` of the window's landmarks with 4 or more
  /// observations have a cluster; otherwise the window is cold-started (after a tracking
  /// break, or when the map was refused several windows in a row).
  double min_known_frames = 0.5;
  double min_known_landmarks = 0.5;
  void Check() const;
  /// Keys: enabled, max_iterations, ba_iterations, adjust_prior, keep_moving_labels,
  /// function_tolerance, fix_known_poses, free_known_frames, min_known_frames, min_known_landmarks.
  void Load(OptionsReader& reader);
};

/// Everything RunClusterSlam needs; the component options are used as given except that
/// `ablation` switches the corresponding component fields on top of them.
struct ClusterSlamOptions {
  /// Eq. 1 with α = 2·10⁻⁵ [ours, measured]: with the model assignment below, the first
  /// clustering only needs the static world as one cluster, and the paper's α = 4·10⁻⁴
  /// splits it into image-compact pieces
  /// (docs/experiments/2026-11-23-backend-with-model-assignment.md). The paper's loop is
  /// `assignment.enabled: false` with `distance.alpha: 4e-4`.
  static MotionDistanceOptions FirstClusteringDistance() {
    MotionDistanceOptions d;
    d.alpha = 2e-5;
    return d;
  }
  MotionDistanceOptions distance = FirstClusteringDistance();
  HacOptions hac;
  ConsensusOptions consensus;
  MotionEstimationOptions motion;
  /// [ours] iterations >= 2 test every landmark against every cluster's estimated motion
  /// (model_assignment.h) instead of re-running Eq. 1 + HAC on refined positions.
  ModelAssignmentOptions assignment;
  ClusterSlamAblation ablation = ClusterSlamAblation::kNone;
  int max_iterations = 5;        ///< k_max of Algorithm 1 [ours]
  /// [ours] the loop stops when the labelling changed by at most this variation of
  /// information (0 = only when identical up to relabelling): a few ambiguous landmarks
  /// flipping between two models should not cost more full estimations.
  double convergence_vi = 0.02;
  /// [ours] Levenberg–Marquardt iterations of the bundle adjustment in the iterations whose
  /// estimate only feeds the next labelling (0: shape initialisation only); the final
  /// labelling always gets motion.bundle_adjustment.max_iterations. The adjustment is most of
  /// the backend's time, and the model assignment needs the motions only roughly converged.
  int intermediate_ba_iterations = 50;
  /// [ours] iterations >= 2 start the static cluster from the previous estimate
  /// (EstimateMotions' warm_start) instead of a fresh shape initialisation.
  bool warm_start = true;
  /// [ours] a moving cluster given the same landmarks as in the previous iteration keeps its
  /// estimate instead of being re-estimated (MovingClusterCache; identical result, decoupled
  /// adjustment only). Used by the default estimator of RunClusterSlam.
  bool reuse_unchanged_clusters = true;
  int refine_half_window = 2;    ///< [ours] frames each side averaged by RefineTracks; 0 = the
                                 ///< raw back-projections in every iteration
  /// [ours] floor on a keypoint's largest standard deviation, px, applied to the input's
  /// covariances before anything else (backend/covariance_floor.h; 0 = off): a covariance
  /// whose largest axis is below it is scaled up, shape kept. 0.5 px = the frontend's
  /// localisation floor σ_det at level 0 (frontend/keypoint_covariance.h): its covariances
  /// have a largest eigenvalue ≥ 0.55 px² and are never changed; nor is the generator's at its
  /// default 1.5 px (0.75 px²). Floors at and below 0.5 px measured on the generator's 0 px
  /// sequences: docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md.
  double min_pixel_sigma = 0.5;
  /// [ours] Online windows: start from the map's prior (RunClusterSlamWindow).
  WindowPriorOptions window_prior;

  /// ε = 60, chunks 100 / 25 [paper].
  static ClusterSlamOptions Indoor();
  /// ε = 90, chunks 200 / 25 [paper; overlap ours].
  static ClusterSlamOptions Outdoor();
  /// The component options with the ablation applied.
  ClusterSlamOptions Effective() const;
  void Check() const;
  /// Keys: distance, hac, consensus, motion, assignment, window_prior (sections), ablation, max_iterations,
  /// convergence_vi, intermediate_ba_iterations, warm_start, reuse_unchanged_clusters,
  /// refine_half_window.
  void Load(OptionsReader& reader);
};

/// The motion estimation step, injectable for tests; the default is EstimateMotions.
/// The last argument is the previous iteration's estimate (null in the first), for a warm start.
using MotionEstimator = std::function<MotionEstimate(
    const TrackletTable&, const StereoCamera&, FrameRange, const std::vector<int>&,
    const MotionEstimationOptions&, const MotionEstimate*)>;

/// Runs Algorithm 1 on the observations of `range`. Result labels: 0 static, 1..K moving,
/// -1 not clustered (too few observations or a cluster below the minimum size). Stops when
/// the labelling equals the previous one up to relabelling (VI = 0; the previous estimate is
/// kept) or after max_iterations. result.iterations records every iteration.
BackendResult RunClusterSlam(const TrackletTable& table, const StereoCamera& camera,
                             FrameRange range, const ClusterSlamOptions& options);
BackendResult RunClusterSlam(const TrackletTable& table, const StereoCamera& camera,
                             FrameRange range, const ClusterSlamOptions& options,
                             const MotionEstimator& estimator);

/// One online window [ours]. With a usable `prior` (see WindowPriorOptions; may be null) the
/// first pairwise clustering is skipped: the prior's labels (only the static ones unless
/// window_prior.keep_moving_labels) and camera poses (the frames it
/// lacks registered on its static landmarks, CompleteCameraPoses) give a first estimate
/// without adjustment, static landmarks at the map's positions and moving clusters
/// shape-initialised from the window's observations. Then up to window_prior.max_iterations
/// rounds of: model assignment (landmarks new to the map join the model that explains their
/// track, wrongly labelled ones move, outliers are re-clustered with Eq. 1 + HAC, clusters that
/// move alike merge), and an estimation with window_prior.ba_iterations LM iterations whose
/// static cluster starts from the previous estimate. Stops early when the labelling is
/// stable (convergence_vi). Otherwise, the cold start: RunClusterSlam. result.warm_started
/// says which ran.
BackendResult RunClusterSlamWindow(const TrackletTable& table, const StereoCamera& camera,
                                   FrameRange range, const ClusterSlamOptions& options,
                                   const WindowPrior* prior);

/// Whether `prior` is usable for a window over `range` of `table` under `options` (see
/// WindowPriorOptions); `why` (may be null) receives the reason when it is not.
bool PriorIsUsable(const WindowPrior& prior, const TrackletTable& table, FrameRange range,
                   const WindowPriorOptions& options, std::string* why = nullptr);

/// The clustering half of one iteration: per-chunk distance + HAC, then consensus, relabelled
/// static-first (0 static, 1..K moving, -1 none). `previous` (may be null) is the previous
/// iteration's labelling for the static rule. Options are used as given (no ablation applied).
std::vector<int> ClusterLandmarks(const TrackletTable& table, const PointTracks& tracks,
                                  FrameRange range, const ClusterSlamOptions& options,
                                  const std::vector<int>* previous,
                                  ConsensusSummary* summary = nullptr);

}  // namespace cslam
