#include "system/pipeline/disparity_offset_calibration.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <spdlog/fmt/fmt.h>

#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/pipeline/pipeline_options.h"

namespace cslam {

void CalibrationOptions::Check() const {
  CheckOption(disparity_offset_frames >= 3, "disparity_offset_frames",
              "must be >= 3 frames", disparity_offset_frames);
  CheckOption(disparity_offset_min_sigmas >= 0 && std::isfinite(disparity_offset_min_sigmas),
              "disparity_offset_min_sigmas", "must be finite and >= 0",
              disparity_offset_min_sigmas);
  CheckOption(disparity_offset_min_px >= 0 && std::isfinite(disparity_offset_min_px),
              "disparity_offset_min_px", "must be finite and >= 0 px",
              disparity_offset_min_px);
  CheckOption(disparity_offset_max_yaw_rate > 0 && !std::isnan(disparity_offset_max_yaw_rate),
              "disparity_offset_max_yaw_rate",
              "must be > 0 rad/s (.inf turns the check off)", disparity_offset_max_yaw_rate);
  CheckOption(disparity_offset_yaw_span_s > 0 && std::isfinite(disparity_offset_yaw_span_s),
              "disparity_offset_yaw_span_s", "must be finite and > 0 s",
              disparity_offset_yaw_span_s);
  CheckSection("disparity_offset", [&] { disparity_offset.Check(); });
}

void CalibrationOptions::Load(OptionsReader& r) {
  r.Read("estimate_disparity_offset", &estimate_disparity_offset);
  r.Read("disparity_offset_frames", &disparity_offset_frames);
  r.Read("disparity_offset_min_sigmas", &disparity_offset_min_sigmas);
  r.Read("disparity_offset_min_px", &disparity_offset_min_px);
  r.Read("disparity_offset_max_yaw_rate", &disparity_offset_max_yaw_rate);
  r.Read("disparity_offset_yaw_span_s", &disparity_offset_yaw_span_s);
  r.ReadSection("disparity_offset", &disparity_offset);
}

double PeakYawRate(const std::vector<Pose>& world_from_cam, FrameRange range,
                   const std::vector<double>& timestamps, double min_span_s) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const int n = static_cast<int>(world_from_cam.size());
  if (n < 2 || n != range.size() || range.begin < 0 ||
      range.end > static_cast<int>(timestamps.size()))
    return nan;
  const auto time = [&](int i) { return timestamps[range.begin + i]; };
  for (int i = 0; i + 1 < n; ++i)
    if (!(time(i + 1) > time(i))) return nan;
  const auto rate = [&](int i, int j) {
    const Eigen::Matrix3d r = world_from_cam[i].linear().transpose() * world_from_cam[j].linear();
    // The later camera's forward axis in the earlier one's frame; turning left (towards −x)
    // is a positive rotation about −y.
    return std::atan2(-r(0, 2), r(2, 2)) / (time(j) - time(i));
  };
  double peak = 0.0;
  bool any = false;
  for (int i = 0, j = 1; i + 1 < n; ++i) {
    j = std::max(j, i + 1);
    while (j < n && time(j) - time(i) < min_span_s) ++j;
    if (j == n) break;
    const double w = rate(i, j);
    if (!any || std::abs(w) > std::abs(peak)) peak = w;
    any = true;
  }
  return any ? peak : rate(0, n - 1);
}

DisparityOffsetCalibrator::DisparityOffsetCalibrator(const CalibrationOptions& options,
                                                     CalibratedBackend inner,
                                                     std::vector<double> timestamps)
    : options_(options), inner_(std::move(inner)), timestamps_(std::move(timestamps)) {}

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
  } else if (record.yaw_rate = PeakYawRate(m.world_from_cam, record.frames, timestamps_,
                                            options_.disparity_offset_yaw_span_s);
             std::abs(record.yaw_rate) > options_.disparity_offset_max_yaw_rate) {
    // Not estimated: it would measure the exposures' timing as much as the pair (see the
    // option's comment).
    record.decision = fmt::format(
        "not estimated: the camera turned at {:+.3f} rad/s in these frames (max_yaw_rate "
        "{:.3f}); a left/right exposure offset would look like a disparity offset",
        record.yaw_rate, options_.disparity_offset_max_yaw_rate);
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
  log->info("disparity offset over frames {}..{} (yaw rate {:+.3f} rad/s): {:+.4f} ± {:.4f} px "
            "({} landmarks, {} observations, {:.1f} s): {}",
            record.frames.begin, record.frames.end - 1, record.yaw_rate, d.offset_px, d.sigma_px,
            d.landmarks, d.observations, record.seconds, record.decision);
  return record;
}

}  // namespace cslam
