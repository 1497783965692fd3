#pragma once
// Motion-model assignment [ours, beyond the paper]: once every cluster has an estimated
// trajectory, each landmark is tested against every cluster's motion instead of against other
// landmarks one pair at a time.
//
// Why: the pairwise motion distance (Eq. 1) sees one scalar distance per frame between two
// noisy points, so a car 30 m away and a static point next to it are often indistinguishable
// pair by pair (measured on the synthetic generator: many static–moving pairs carry little χ²
// excess over their whole co-observation), while a landmark's whole track tested against a
// cluster's estimated motion separates the same car by a reduced χ² far above the ≈ 1 of
// static points (docs/experiments/2026-11-23-backend-with-model-assignment.md). The pairwise
// clustering then only has to produce a
// first partition whose largest cluster is the static world; this step
//   - reassigns each landmark to the motion model that explains its track best (ties go to
//     the static cluster: a landmark that fits the static world is labelled static),
//   - marks as outliers the landmarks no model explains (to be re-clustered by the caller),
//   - merges a cluster into another whose motion explains its landmarks about as well as its
//     own (the static world split into pieces becomes one cluster again),
//   - dissolves a moving cluster that has not earned its existence [ours, for real tracks]:
//     too few of its landmarks fit its own motion (a group of unrelated bad tracks that the
//     re-clustering put together), or the static world's motion explains its tracks within
//     their covariances (backend/moving_test.h: a piece of the static world that its own
//     6 DoF per frame over-fit), or its motion displaces its points by less than a small
//     fraction of their range: significant but too small for a body (a few tracks drifting
//     alike pass the test). Its landmarks go to the best remaining model, or stay unlabelled.
//
// Real tracks (KITTI raw 0005, docs/experiments/2026-12-01-clustering-on-a-real-drive.md):
// under the estimated static motion, most static landmarks have a small cost but the tail is
// heavy: single KLT jumps and tracks that follow no physical point
// (occlusion boundaries). The cost therefore leaves out up to `max_dropped_samples` samples
// beyond a χ² gate, and unlabelled landmarks that fit nothing are not re-clustered again.
//
// Test of landmark i against model q: its camera-frame back-projections X_t (covariance Σ_t)
// mapped into q's frame, Y_t = T^{qc}_t X_t with covariance R Σ_t Rᵀ, should be one point.
// Cost = reduced χ² of the information-weighted mean: Σ_t ‖Y_t − Ȳ‖² / (3n − 3).
#include <vector>

#include "backend/motion_estimation.h"
#include "backend/moving_test.h"
#include "backend/point_tracks.h"
#include "core/options_reader.h"

namespace cslam {

/// Thresholds of the model assignment; costs are reduced χ² (≈ 1 for a correct model).
struct ModelAssignmentOptions {
  bool enabled = true;          ///< false: the paper's loop (re-cluster with Eq. 1 every iteration)
  double fit_threshold = 3.0;   ///< a landmark whose best cost exceeds this is an outlier
  double static_margin = 0.3;   ///< added to every other model's cost than the favoured one
  /// [ours] In a window started from the map (window_prior), the margin favours a labelled
  /// landmark's own model (ties keep the label) instead of the static world; unlabelled
  /// landmarks' ties still go to static. Cold solves (a batch run, a first window) ignore it.
  /// false: the static world is favoured for every landmark. The outdoor preset sets it.
  bool favour_own_label = false;
  /// [ours] A moving cluster whose landmarks form groups more than this far apart (in its own
  /// frame, nothing between them) is split into one cluster per group after the final check
  /// (backend/place_split.h), and two moving clusters so far apart are not merged, here or in
  /// the map: a road vehicle's visible points leave no 4 m stretch empty, while cars one behind
  /// the other, or two crossing, share one motion within the depth noise beyond ~30 m and are
  /// metres apart (docs/experiments/2026-12-07-far-cars-labelled-static-online.md). 0 = off.
  double split_gap_m = 4.0;
  double min_coverage = 0.8;    ///< a model must have a pose at this fraction of the track's frames
  double merge_fraction = 0.9;  ///< merge p into q when this fraction of p's landmarks is
                                ///< covered by q and fits it (cost <= fit_threshold), and
  double merge_ratio = 1.2;     ///< their mean cost under q <= max(ratio × own, own + slack)
  double merge_slack = 0.2;
  double outlier_alpha = 4e-4;  ///< image-prior weight (Eq. 1) when re-clustering outliers:
                                ///< objects are told apart by where they are in the image
  int min_outlier_cluster = 5;  ///< smaller groups of re-clustered outliers stay unlabelled
  double outlier_max_extent_m = 5.0;  ///< [ours] motion_distance.max_extent_m when re-clustering
                                      ///< outliers: movers are small bodies, so two landmarks
                                      ///< whose mean distance is beyond it are two bodies; 0 = off
  int max_dropped_samples = 0;  ///< [ours] per track, samples beyond sample_gate_chi2 left out
                                ///< of its cost (one KLT jump should not make a mover); 0 = off
  double sample_gate_chi2 = 16.27;  ///< χ²(3) 0.999: a sample's own χ² to be left out
  int min_cluster_landmarks = 5;      ///< [ours] a moving cluster is dissolved when fewer of
                                      ///< its landmarks fit its own motion; 0 = off
  double min_own_fit_fraction = 0.7;  ///< ... or when fewer than core_cluster_landmarks and
  int core_cluster_landmarks = 10;    ///< less than this fraction of its landmarks fit it
  bool test_moving = true;            ///< ... or when the static world explains its tracks
  MovingTestOptions moving_test;      ///< (section "moving_test"; backend/moving_test.h)
  double min_relative_motion = 0.02;  ///< ... or its motion relative to the static world moves
                                      ///< its points by less than this RMS / mean range; 0 = off
  int max_reclusterings = 2;          ///< [ours] times one landmark is handed out for
                                      ///< re-clustering over the loop (with a counter)

  void Check() const;
  void Load(OptionsReader& reader);
};

/// Result of one assignment round.
struct ModelAssignment {
  std::vector<int> labels;    ///< [landmark id]: new label (a label of the input), -1 none
  std::vector<int> outliers;  ///< landmark ids no model explains, to be re-clustered (labels -1)
  int unexplained = 0;        ///< landmarks no model explains left unlabelled: re-clustered
                              ///< max_reclusterings times already
  int reassigned = 0;         ///< landmarks whose label changed to another model
  int merges = 0;             ///< clusters merged into another
  int dissolved = 0;          ///< moving clusters dissolved (see the file comment)
};

/// Reduced χ² of `track` under the motion of cluster `label` in `estimate` (0 = static: the
/// world frame), over the track's samples where that cluster has a pose; negative when those
/// samples are fewer than 4 or than `min_coverage` of the track. Up to `max_dropped` samples
/// whose own χ² exceeds `gate_chi2` are left out (worst first, at least 4 kept; dof shrinks).
double ModelCost(const PointTrack& track, const MotionEstimate& estimate, int label,
                 double min_coverage, int max_dropped = 0, double gate_chi2 = 16.27);

/// How far cluster `label`'s estimated motion moves its points in the world: RMS over its
/// landmarks (`labels`, positions from `estimate`) and frames of the distance of each point
/// from its mean world position, divided by the points' mean distance from the camera; 0 for
/// a cluster held still, negative without a trajectory or points.
double RelativeMotion(const MotionEstimate& estimate, const std::vector<int>& labels, int label);

/// The moving-or-static test (backend/moving_test.h) of cluster `label` of `labels`: its
/// landmarks' `tracks` under the static world's motion in `estimate` against its own.
/// `moving` false without a trajectory.
MovingTestResult TestClusterMoving(const PointTracks& tracks, const std::vector<int>& labels,
                                   const MotionEstimate& estimate, int label,
                                   const MovingTestOptions& options);

/// The final word on the moving clusters of `estimate` [ours]: a cluster whose landmarks
/// mostly do not fit its own motion (min_cluster_landmarks, core_cluster_landmarks,
/// min_own_fit_fraction) or that fails the moving test (test_moving) is removed; its
/// landmarks join the static world (placed at the mean of their static-mapped samples) when
/// they fit it, and become unlabelled (-1) when not. The loop's last re-clustering of outliers
/// makes clusters no assignment round has judged yet; this judges them. Returns how many
/// clusters were removed.
int DissolveUnsupportedClusters(const PointTracks& tracks, const ModelAssignmentOptions& options,
                                MotionEstimate* estimate);

/// One round of reassignment, outlier detection, dissolution and merging of `labels`
/// ([landmark id], -1 none) given the motions estimated for them. `tracks` = camera-frame
/// back-projections (BackProjectTracks); landmarks with fewer than 4 samples keep their label
/// (-1 when their cluster is dissolved). `reclusterings` (may be null: no limit) [landmark id]
/// counts how often each landmark was returned in `outliers` over the caller's loop; this call
/// increments it for the ones it returns.
ModelAssignment AssignToMotionModels(const PointTracks& tracks, const std::vector<int>& labels,
                                     const MotionEstimate& estimate,
                                     const ModelAssignmentOptions& options,
                                     std::vector<int>* reclusterings = nullptr);

}  // namespace cslam
