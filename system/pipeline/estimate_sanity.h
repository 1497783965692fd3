#pragma once
// Whether a backend window's estimate is usable: stricter than "every pose is finite". An
// estimate whose camera jumps, in one frame, farther than anything the stereo pair measured
// in that window, or many of whose landmarks lie far beyond the measured depth range, came
// from a diverged solve (measured: Full BA on generated outdoor sequences before the shape
// initialisation's fusion gate, with absurd camera steps;
// docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md) and must not enter the
// map. The depth range is the input's own: the largest depth f·b/d over the
// window's observations with positive disparity d.
#include <string>

#include "backend/motion_estimation.h"
#include "core/options_reader.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Thresholds, in units of the window's largest measured depth D.
struct EstimateSanityOptions {
  /// A camera translation between consecutive frames above this × D is absurd: the camera
  /// cannot move farther in one frame than the farthest point it measured [ours].
  double max_step_depths = 1.0;
  /// A landmark farther than this × D from a camera that observes it is absurd [ours].
  double far_landmark_depths = 10.0;
  /// More than this fraction of absurd landmarks makes the estimate unusable [ours]. Not 0:
  /// a Full BA (or a one-cluster window) legitimately pushes car points that move with the
  /// camera towards infinity along their rays — measured on generated outdoor sequences,
  /// batch and in one-iteration windows, a few percent of the landmarks with a good camera
  /// (docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md); 0.25 leaves ample
  /// headroom.
  double max_far_landmark_fraction = 0.25;
  /// A moving cluster's pose in one frame is absurd when it places the cluster's landmarks
  /// observed there, in the median, more than this × farther from the camera than their own
  /// stereo measurements say (or behind it) [ours]. 0 turns the test off.
  double max_cluster_depth_ratio = 3.0;

  void Check() const;
  void Load(OptionsReader& reader);
};

/// The verdict, with the reason when the estimate is refused.
struct EstimateSanity {
  bool usable = true;
  std::string reason;           ///< empty when usable
  double max_depth_m = 0;       ///< D: largest measured depth in the window
  double max_step_m = 0;        ///< largest camera translation between consecutive frames
  int landmarks = 0;            ///< landmarks with a label and a finite position
  int far_landmarks = 0;        ///< of those, farther than far_landmark_depths × D
};

/// Judges `estimate` (over estimate.range) against the observations of `table` that produced
/// it. Non-finite or missing poses are refused too.
EstimateSanity JudgeEstimate(const MotionEstimate& estimate, const TrackletTable& table,
                             const StereoCamera& camera, const EstimateSanityOptions& options);

/// Removes from `estimate` the moving-cluster poses that fail max_cluster_depth_ratio, and a
/// cluster left without poses (its landmarks become unused, -1). Such a pose comes from a solve
/// that diverged on that frame — measured on a generated outdoor sequence online: a car's pose
/// placing its observed points far beyond what their disparities measure, which the map
/// stitched into an absurd trajectory (docs/experiments/2026-12-03-implausible-cluster-poses.md)
/// — while the rest of the window
/// is sound, so the window is kept and only those poses go. Returns the poses removed.
int DropImplausibleClusterPoses(MotionEstimate* estimate, const TrackletTable& table,
                                const StereoCamera& camera, const EstimateSanityOptions& options);

}  // namespace cslam
