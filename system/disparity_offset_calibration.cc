#include "system/disparity_offset_calibration.h"

#include <cmath>
#include <utility>

#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/pipeline_options.h"

namespace cslam {

void CalibrationOptions::Check() const {
  CheckOption(disparity_offset_frames >= 3, "calibration.disparity_offset_frames",
              "must be >= 3 frames", disparity_offset_frames);
  CheckOption(disparity_offset_min_sigmas >= 0 && std::isfinite(disparity_offset_min_sigmas),
              "calibration.disparity_offset_min_sigmas", "must be finite and >= 0",
              disparity_offset_min_sigmas);
  CheckOption(disparity_offset_min_px >= 0 && std::isfinite(disparity_offset_min_px),
              "calibration.disparity_offset_min_px", "must be finite and >= 0 px",
              disparity_offset_min_px);
  try {
    disparity_offset.Check();
  } catch (const ConfigError& e) {
    throw ConfigError(std::string("calibration.disparity_offset.") + e.what());
  }
}

void CalibrationOptions::Load(OptionsReader& r) {
  r.Read("estimate_disparity_offset", &estimate_disparity_offset);
  r.Read("disparity_offset_frames", &disparity_offset_frames);
  r.Read("disparity_offset_min_sigmas", &disparity_offset_min_sigmas);
  r.Read("disparity_offset_min_px", &disparity_offset_min_px);
  auto section = r.Section("disparity_offset");
  disparity_offset.Load(section);
  section.Finish();
  r.Finish();
}

DisparityOffsetCalibrator::DisparityOffsetCalibrator(const CalibrationOptions& options,
                                                     CalibratedBackend inner)
    : options_(options), inner_(std::move(inner)) {}

BackendResult DisparityOffsetCalibrator::operator()(const TrackletTable& table,
                                                    const StereoCamera& camera, FrameRange range,
                                                    const PipelineOptions& options,
                                                    const WindowPrior* prior) {
  std::optional<BackendResult> reusable;
  if (!record_) record_ = Calibrate(table, camera, range, options, prior, &reusable);
  if (!record_->applied) {
    if (reusable) return std::move(*reusable);
    return inner_(table, camera, range, options, prior);
  }
  return inner_(CorrectDisparities(table, record_->applied_px), camera, range, options, prior);
}

DisparityOffsetCalibration DisparityOffsetCalibrator::Calibrate(
    const TrackletTable& table, const StereoCamera& camera, FrameRange range,
    const PipelineOptions& options, const WindowPrior* prior,
    std::optional<BackendResult>* reusable) {
  const Timer timer;
  DisparityOffsetCalibration record;
  record.frames = {range.begin, std::min(range.end, range.begin + options_.disparity_offset_frames)};
  // The motion to start from: the backend's own estimate over the calibration frames (the
  // call itself when it spans no more; kept for reuse when nothing is applied).
  BackendResult motion;
  if (record.frames == range) {
    *reusable = inner_(table, camera, range, options, prior);
    motion = **reusable;
  } else {
    // Cold: the prior describes the call's range, not this slice.
    motion = inner_(table.Slice(record.frames), camera, record.frames, options, nullptr);
  }
  const MotionEstimate& m = motion.estimate;
  auto log = GetLogger("system");
  if (m.range != record.frames || static_cast<int>(m.world_from_cam.size()) != m.range.size()) {
    record.decision = "no camera motion over the calibration frames";
  } else {
    record.estimate = EstimateDisparityOffset(table, camera, record.frames, m.world_from_cam,
                                              options_.disparity_offset, m.landmark_cluster);
    const DisparityOffset& d = record.estimate;
    const double needed = std::max(options_.disparity_offset_min_sigmas * d.sigma_px,
                                   options_.disparity_offset_min_px);
    if (!d.usable) {
      record.decision = "not estimated: " + d.reason;
    } else if (std::abs(d.offset_px) < needed) {
      record.decision = "not applied: |δ| below max(min_sigmas σ, min_px)";
    } else {
      record.applied = true;
      record.applied_px = d.offset_px;
      record.decision = "applied";
      reusable->reset();  // estimated from uncorrected observations
    }
  }
  record.seconds = timer.ElapsedS();
  const DisparityOffset& d = record.estimate;
  log->info("disparity offset over frames {}..{}: {:+.4f} ± {:.4f} px ({} landmarks, {} "
            "observations, {:.1f} s): {}",
            record.frames.begin, record.frames.end - 1, d.offset_px, d.sigma_px, d.landmarks,
            d.observations, record.seconds, record.decision);
  return record;
}

}  // namespace cslam
