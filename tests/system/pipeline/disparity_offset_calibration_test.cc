#include "system/pipeline/disparity_offset_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "backend/disparity_offset.h"
#include "core/errors.h"
#include "system/pipeline/pipeline.h"
#include "tests/backend/test_scene.h"

namespace cslam {
namespace {

// A static street (tests/backend/test_scene.h: points 4–80 m ahead, the camera driving 1 m a
// frame, 0.3 px noise) with every right column moved by `shift` px, so the δ that undoes it
// is +shift. Static on purpose: on the generator's outdoor scenes with moving bodies the
// estimate is not yet reliable (docs/backend.md, "Disparity offset"). The camera turns right by
// `yaw_per_frame` rad a frame at 10 frames/s; the default, 0.01 rad/s, is within the
// calibration's max_yaw_rate.
RunInput ShiftedStreet(double shift, double yaw_per_frame = 0.001) {
  const auto body = testing::TestBody{testing::RandomPoints(600, {-15, -3, 4}, {15, 3, 80}, 7),
                                      [](int) { return Pose::Identity(); }};
  auto cam = [yaw_per_frame](int t) {
    return testing::YawPose(yaw_per_frame * t, Eigen::Vector3d(0.1 * t, 0, 1.0 * t));
  };
  const testing::TestScene scene =
      testing::MakeScene(testing::SyntheticCamera(true), {body}, 36, cam, 0.3, 0.3, 8);
  RunInput in;
  in.name = "street";
  in.kind = InputKind::kSynthetic;
  in.camera = scene.camera;
  for (int f = 0; f < 36; ++f) in.timestamps.push_back(0.1 * f);
  in.gt_world_from_cam = scene.world_from_cam;
  in.observations = CorrectDisparities(scene.table, -shift);
  return in;
}

PipelineOptions CalibratingOnline() {
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.mode = RunMode::kOnline;
  o.online.sequential = true;
  o.backend.max_iterations = 3;
  o.calibration.estimate_disparity_offset = true;
  return o;
}

// uR of landmark `l` at frame `f` in `t` (NaN when it is not seen there).
double RightColumn(const TrackletTable& t, int l, int f) {
  if (f >= t.num_frames()) return NAN;
  for (const ObservationRef& r : t.ObservationsAt(f))
    if (t.Get(r).landmark == l) return t.Get(r).x(2);
  return NAN;
}

TEST(DisparityOffsetCalibrator, EstimatesAnInjectedOffsetOnceAndCorrectsEveryBackendCall) {
  const RunInput in = ShiftedStreet(0.2);
  const PipelineOptions o = CalibratingOnline();
  // The first observation of frame 0, as every backend call receives it.
  const StereoObservation probe = in.observations->Get(in.observations->ObservationsAt(0)[0]);
  std::vector<double> seen;
  const BackendFunction recording = [&](const TrackletTable& t, const StereoCamera& c,
                                        FrameRange r, const PipelineOptions& po, const WindowPrior* prior) {
    seen.push_back(RightColumn(t, probe.landmark, probe.frame));
    return RunBackend(t, c, r, po, prior);
  };
  const PipelineResult r = RunPipeline(in, o, nullptr, nullptr, recording);
  ASSERT_TRUE(r.disparity_offset.has_value());
  const DisparityOffsetCalibration& cal = *r.disparity_offset;
  std::printf("estimated %+.4f ± %.4f px over frames %d..%d: %s\n", cal.estimate.offset_px,
              cal.estimate.sigma_px, cal.frames.begin, cal.frames.end - 1, cal.decision.c_str());
  ASSERT_TRUE(cal.applied) << cal.decision;
  EXPECT_NEAR(cal.applied_px, 0.2, 0.03);
  EXPECT_EQ(cal.frames.size(), o.calibration.disparity_offset_frames);
  // The calibration's own call (on the uncorrected frames), then every window corrected.
  ASSERT_GE(seen.size(), 3u);
  EXPECT_DOUBLE_EQ(seen[0], probe.x(2));
  for (size_t k = 1; k < seen.size(); ++k) {
    if (std::isfinite(seen[k])) {
      EXPECT_DOUBLE_EQ(seen[k], probe.x(2) - cal.applied_px) << k;
    }
  }
}

TEST(DisparityOffsetCalibrator, LeavesTheObservationsAloneWhenThereIsNoOffset) {
  const RunInput in = ShiftedStreet(0.0);
  PipelineOptions o = CalibratingOnline();
  o.mode = RunMode::kBatch;
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_TRUE(r.disparity_offset.has_value());
  const DisparityOffsetCalibration& cal = *r.disparity_offset;
  std::printf("estimated %+.4f ± %.4f px: %s\n", cal.estimate.offset_px, cal.estimate.sigma_px,
              cal.decision.c_str());
  ASSERT_TRUE(cal.estimate.usable) << cal.estimate.reason;
  EXPECT_NEAR(cal.estimate.offset_px, 0.0, 0.03);
  EXPECT_FALSE(cal.applied);
  EXPECT_EQ(cal.applied_px, 0.0);
}

// A turn with a left/right exposure offset Δt: every right column moves by f·ω·Δt while the
// camera turns at ω, which the estimator cannot tell from a disparity offset of the pair. Here
// ω = 0.1 rad/s and Δt = 2.3 ms (what KITTI raw 0005 shows,
// docs/experiments/2026-12-03-disparity-offset-follows-yaw-rate.md): 0.17 px
// that would be applied to every later frame, turning or not.
TEST(DisparityOffsetCalibrator, DoesNotEstimateWhileTheCameraTurns) {
  const double shift = testing::SyntheticCamera(true).fx * 0.1 * 0.0023;
  const RunInput in = ShiftedStreet(shift, 0.01);
  PipelineOptions o = CalibratingOnline();
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_TRUE(r.disparity_offset.has_value());
  const DisparityOffsetCalibration& cal = *r.disparity_offset;
  std::printf("yaw rate %+.4f rad/s: %s\n", cal.yaw_rate, cal.decision.c_str());
  EXPECT_FALSE(cal.applied);
  EXPECT_EQ(cal.applied_px, 0.0);
  EXPECT_FALSE(cal.estimate.usable);
  EXPECT_NE(cal.decision.find("turned"), std::string::npos) << cal.decision;
  // Turning right (about +y): a negative yaw rate, from the backend's own motion.
  EXPECT_NEAR(cal.yaw_rate, -0.1, 0.01);

  // The check, not the data, stopped it: allowed to, it applies what the turn made.
  o.calibration.disparity_offset_max_yaw_rate = 1.0;
  const PipelineResult allowed = RunPipeline(in, o);
  ASSERT_TRUE(allowed.disparity_offset.has_value());
  EXPECT_TRUE(allowed.disparity_offset->applied) << allowed.disparity_offset->decision;
  EXPECT_NEAR(allowed.disparity_offset->applied_px, shift, 0.03);
}

// Frames 10..30 of a run at 10 frames/s, the camera's heading `heading(f)` rad (+ = left).
std::vector<Pose> Headings(const std::function<double(int)>& heading) {
  std::vector<Pose> poses;
  // YawPose turns about +y, to the right.
  for (int f = 10; f < 31; ++f) poses.push_back(testing::YawPose(-heading(f), Eigen::Vector3d(f, 0, 2 * f)));
  return poses;
}

TEST(PeakYawRate, IsTheSteadyTurnsRateWithItsSign) {
  std::vector<double> times(40);
  for (int f = 0; f < 40; ++f) times[f] = 5.0 + 0.1 * f;
  const auto left = Headings([](int f) { return 0.3 + 0.02 * (f - 10); });  // 0.2 rad/s
  EXPECT_NEAR(PeakYawRate(left, {10, 31}, times, 1.0), 0.2, 1e-9);
  const auto right = Headings([](int f) { return -0.02 * (f - 10); });
  EXPECT_NEAR(PeakYawRate(right, {10, 31}, times, 1.0), -0.2, 1e-9);
  // A span longer than the frames: the whole range's.
  EXPECT_NEAR(PeakYawRate(left, {10, 31}, times, 5.0), 0.2, 1e-9);
  EXPECT_TRUE(std::isnan(PeakYawRate(left, {10, 31}, std::vector<double>(20, 0.0), 1.0)));
  EXPECT_TRUE(std::isnan(PeakYawRate(left, {10, 31}, std::vector<double>(40, 1.0), 1.0)));
  EXPECT_TRUE(std::isnan(PeakYawRate({left[0]}, {10, 11}, times, 1.0)));
}

TEST(PeakYawRate, SeesBothHalvesOfAnSBendWhoseNetTurnIsNil) {
  std::vector<double> times(40);
  for (int f = 0; f < 40; ++f) times[f] = 0.1 * f;
  // Left at 0.2 rad/s for 1 s, right at 0.2 rad/s for 1 s: back to the first heading.
  const auto s_bend = Headings([](int f) { return f <= 20 ? 0.02 * (f - 10) : 0.2 - 0.02 * (f - 20); });
  EXPECT_NEAR(PeakYawRate(s_bend, {10, 31}, times, 5.0), 0.0, 1e-9);  // the net rate
  EXPECT_NEAR(std::abs(PeakYawRate(s_bend, {10, 31}, times, 1.0)), 0.2, 1e-9);
  EXPECT_NEAR(std::abs(PeakYawRate(s_bend, {10, 31}, times, 0.5)), 0.2, 1e-9);
}

TEST(DisparityOffsetCalibrator, IsNotRunWhenSwitchedOff) {
  PipelineOptions o = CalibratingOnline();
  o.calibration.estimate_disparity_offset = false;
  o.backend.max_iterations = 1;
  const PipelineResult r = RunPipeline(ShiftedStreet(0.2), o);
  EXPECT_FALSE(r.disparity_offset.has_value());
}

// The ConfigError message of `o.Check()`; "" when it accepts `o`.
std::string CheckError(const CalibrationOptions& o) {
  try {
    o.Check();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(CalibrationOptions, CheckNamesTheBadKey) {
  EXPECT_EQ(CheckError({}), "");
  const auto with = [](auto set) {
    CalibrationOptions o;
    set(o);
    return CheckError(o);
  };
  EXPECT_NE(with([](auto& o) { o.disparity_offset_frames = 2; })
                .find("disparity_offset_frames"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.disparity_offset_max_yaw_rate = 0; })
                .find("disparity_offset_max_yaw_rate"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.disparity_offset_yaw_span_s = 0; })
                .find("disparity_offset_yaw_span_s"),
            std::string::npos);
  EXPECT_NE(with([](auto& o) { o.disparity_offset.robust_threshold_chi2 = -1; })
                .find("disparity_offset.robust_threshold_chi2"),
            std::string::npos);
}

}  // namespace
}  // namespace cslam
