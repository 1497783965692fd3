#pragma once
// The run's self-calibration of the stereo pair's disparity offset (calibration.* options,
// docs/usage.md): before the backend's estimates count, δ is estimated from the first
// frames (backend/disparity_offset.h) and, when the data pin it down, every observation the
// backend is given is corrected by it.
//
// It sits between the pipeline and its backend function, so both modes get the same
// treatment without the pipeline knowing: the first backend call (the first online window,
// or the batch call) first runs the backend over the calibration frames — the online window
// itself when it is that long — estimates δ against that motion, and, if δ is applied, runs
// on the corrected observations. Every later call is corrected by the same δ. The frontend's
// table itself is left as measured (its outputs, overlays, the sanity check's χ² by 0.1 px).
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "backend/backend_result.h"
#include "backend/disparity_offset.h"
#include "backend/window_prior.h"
#include "core/options_reader.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

struct PipelineOptions;

/// Options of the self-calibration (YAML section `calibration`).
struct CalibrationOptions {
  /// Estimate the disparity offset at the start of the run and apply it when significant.
  bool estimate_disparity_offset = false;
  /// Frames from the start of the first backend call the estimate uses (the first online
  /// window is 30; batch runs use the same frames, so both modes find the same δ).
  int disparity_offset_frames = 30;
  /// δ is applied only when |δ| ≥ this many σ ...
  double disparity_offset_min_sigmas = 3.0;
  /// ... and |δ| ≥ this, px: the matcher's own systematic error on rendered images with exact
  /// ground truth is ±0.02–0.03 px (docs/frontend.md), so a smaller δ is not a calibration
  /// error one can tell from it.
  double disparity_offset_min_px = 0.03;
  /// δ is not estimated when the camera's heading changes faster than this anywhere in the
  /// calibration frames, rad/s (PeakYawRate over spans of yaw_span_s). Why: a
  /// time offset between the left and right exposures shifts every right column by
  /// f·ω·Δt, a disparity offset that follows the yaw rate ω. On KITTI raw 0005 the estimate
  /// swung with the turns (docs/experiments/2026-12-03-disparity-offset-follows-yaw-rate.md);
  /// below the default limit the bias this leaves is under min_px.
  double disparity_offset_max_yaw_rate = 0.015;
  /// Shortest span, s, the yaw rate is measured over. Not frame to frame: the estimated
  /// motion's per-frame yaw is noisy (KITTI odometry clip_a, driving straight: up to
  /// 0.023 rad/s frame to frame, ≤ 0.010 rad/s over 1 s, the ground truth's ≤ 0.008). The
  /// largest over every span, not their mean: over an S-bend the mean is ≈ 0 while either
  /// half biases δ (raw 0005 frames 50–79: net −0.007 rad/s, δ +0.16 px).
  double disparity_offset_yaw_span_s = 1.0;
  /// The estimator's own options (section calibration.disparity_offset).
  DisparityOffsetOptions disparity_offset;

  /// Throws ConfigError naming the key (calibration.…) that breaks its rule.
  void Check() const;
  void Load(OptionsReader& reader);
};

/// What the calibration did; written to metrics.json (`calibration`) and the log.
struct DisparityOffsetCalibration {
  FrameRange frames;          ///< the frames δ was estimated over
  DisparityOffset estimate;   ///< δ, σ and the solve's counts
  /// Largest yaw rate of the starting motion over `frames` (PeakYawRate), rad/s (+ = heading
  /// turning left, about the camera's −y); NaN when the motion or the frame times are missing.
  double yaw_rate = std::numeric_limits<double>::quiet_NaN();
  bool applied = false;       ///< the backend was given corrected observations
  double applied_px = 0.0;    ///< δ applied (0 when not)
  std::string decision;       ///< why it was or was not applied
  double seconds = 0.0;       ///< wall time of the extra backend call and the estimate
};

/// The pipeline's backend function, wrapped (same signature as BackendFunction).
using CalibratedBackend =
    std::function<BackendResult(const TrackletTable&, const StereoCamera&, FrameRange,
                                const PipelineOptions&, const WindowPrior*)>;

/// The yaw rate (rad/s, + = turning left) of largest magnitude over the spans of
/// `world_from_cam` (frames `range`; camera x right, y down, z forward) from each frame to the
/// first one at least `min_span_s` later: the net rotation about the span's first camera's y
/// axis over the span's time (timestamps[frame]). The whole range's when it is shorter than
/// `min_span_s`. NaN when there are fewer than two poses, or the times do not cover `range`
/// or do not increase.
double PeakYawRate(const std::vector<Pose>& world_from_cam, FrameRange range,
                   const std::vector<double>& timestamps, double min_span_s);

/// Wraps `inner` (the run's backend call) with the calibration of options.calibration.
/// Calls come from one thread at a time (the backend stage); Record() is read after the run.
class DisparityOffsetCalibrator {
 public:
  /// `timestamps`: seconds per frame of the run (for the yaw-rate check).
  DisparityOffsetCalibrator(const CalibrationOptions& options, CalibratedBackend inner,
                            std::vector<double> timestamps = {});

  /// The first call estimates δ (see the file comment); every call runs `inner` on the
  /// observations corrected by the δ applied.
  BackendResult operator()(const TrackletTable& table, const StereoCamera& camera,
                           FrameRange range, const PipelineOptions& options,
                           const WindowPrior* prior = nullptr);

  /// What the first call decided; empty before it.
  const std::optional<DisparityOffsetCalibration>& Record() const { return record_; }

 private:
  DisparityOffsetCalibration Calibrate(const TrackletTable& table, const StereoCamera& camera,
                                       FrameRange range, const PipelineOptions& options,
                                       const WindowPrior* prior,
                                       std::optional<BackendResult>* reusable);

  const CalibrationOptions& options_;
  CalibratedBackend inner_;
  std::vector<double> timestamps_;
  std::optional<DisparityOffsetCalibration> record_;
};

}  // namespace cslam
