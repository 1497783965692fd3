#pragma once
// Self-calibration of a stereo pair's disparity offset δ [ours] from the tracks alone: a
// robust bundle adjustment of the landmarks and camera poses over a range of frames with one
// more global unknown, δ, added to every measured disparity (uR − δ is the corrected right
// column, as FrontendOptions' stereo.disparity_offset_px applies it).
//
// Why it is observable: a wrong δ changes a point's depth by the factor d / (d + δ), which
// depends on the disparity d — so near and far points are stretched differently. Over a
// track, the image flow fixes each point's depth relative to the camera's translation
// (monocular structure); only the right δ makes the stereo depths of near and far points
// agree with one rigid motion. With a single depth (a wall) δ and the translation scale are
// confounded; σ from the inverse Hessian says how well the data pins it
// (docs/backend.md, "Disparity offset").
#include <limits>
#include <string>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Options of EstimateDisparityOffset.
struct DisparityOffsetOptions {
  /// Landmarks seen in fewer frames of the range say nothing about the motion and stay out.
  int min_track_length = 3;
  /// Robust kernel: "huber" or "cauchy"; threshold on the squared whitened residual (χ², 3
  /// dof; 7.815 = its 0.95 quantile, the bundle adjustment's Huber threshold).
  std::string robust_kernel = "cauchy";
  double robust_threshold_chi2 = 7.815;
  /// Floor on a keypoint's largest standard deviation, px (backend/covariance_floor.h; the
  /// backend's ClusterSlamOptions::min_pixel_sigma, so both weigh keypoints alike).
  double min_pixel_sigma = 0.5;
  int max_iterations = 100;  ///< Levenberg–Marquardt iterations per solve
  /// After a first solve on every observation, those with a squared whitened residual above
  /// this (χ²) are left out, and so are landmarks left with fewer than min_track_length: the
  /// moving points the labelling missed and mismatches, which the kernel only down-weights.
  double outlier_chi2 = 50.0;
  /// Largest |δ| the solve may report, px: beyond it the estimate is refused (usable = false).
  double max_offset_px = 2.0;
  /// Leave out the landmarks the motion's labelling put in a moving cluster (label > 0);
  /// static and unlabelled ones stay in. Why: a point moving along the viewing direction
  /// looks like a static point whose stereo depth disagrees with its flow — what δ explains —
  /// and is not always far enough off the camera's motion for the rejection [measured,
  /// docs/experiments/2026-12-01-disparity-offset-self-calibration.md].
  bool exclude_moving = true;

  void Check() const;
  /// Keys: the snake_case field names.
  void Load(OptionsReader& reader);
  bool operator==(const DisparityOffsetOptions&) const = default;
};

/// What EstimateDisparityOffset found.
struct DisparityOffset {
  bool usable = false;  ///< false: too few landmarks, a failed solve or |δ| > max_offset_px
  std::string reason;   ///< why not usable
  double offset_px = 0.0;  ///< δ: add to every measured disparity (uR − δ)
  /// Standard deviation of δ from the inverse Gauss-Newton Hessian of the robust cost
  /// (poses and points marginalised), scaled by the residuals' reduced χ² when it exceeds 1
  /// (the frontend's covariances are not calibrated).
  double sigma_px = std::numeric_limits<double>::infinity();
  double reduced_chi2 = 0.0;  ///< 2 × final robust cost / (residuals − unknowns)
  int landmarks = 0;
  int observations = 0;
  int frames = 0;
  int iterations = 0;

  /// |δ| / σ (0 when not usable).
  double Significance() const;
};

/// δ over `range`: every landmark with at least min_track_length observations in it and the
/// camera poses `world_from_cam` ([frame − range.begin]), adjusted together with δ (the first
/// pose held: the gauge; the scale is the baseline's). Points start at the mean of their
/// back-projections and are placed with the motion held before the first outlier rejection.
/// Not only the landmarks a backend labelled static: a labelling made from uncorrected
/// disparities keeps the points that agree with the wrong δ (an earlier probe on this branch,
/// not re-measured). With options.exclude_moving, the landmarks
/// `landmark_cluster` ([landmark id], may be empty) puts in a moving cluster (> 0) stay out.
DisparityOffset EstimateDisparityOffset(const TrackletTable& table, const StereoCamera& camera,
                                        FrameRange range, const std::vector<Pose>& world_from_cam,
                                        const DisparityOffsetOptions& options,
                                        const std::vector<int>& landmark_cluster = {});

/// The profile of the same robust cost: after the same outlier rejection, for each δ of
/// `offsets`, held fixed, the poses and points adjusted; returns ½Σρ per offset (NaN when there
/// is nothing to adjust). For cost curves (docs, tests).
std::vector<double> ProfileDisparityOffset(const TrackletTable& table, const StereoCamera& camera,
                                           FrameRange range, const std::vector<Pose>& world_from_cam,
                                           const DisparityOffsetOptions& options,
                                           const std::vector<double>& offsets,
                                           const std::vector<int>& landmark_cluster = {});

/// A copy of `table`'s held observations (same landmark ids) with every right column
/// corrected by δ: uR − offset_px, the disparity + offset_px.
TrackletTable CorrectDisparities(const TrackletTable& table, double offset_px);

}  // namespace cslam
