#include "system/run/run_metrics.h"

#include <gtest/gtest.h>

#include "tests/support/poses.h"

namespace cslam {
namespace {

using testing::Translation;

// A map whose camera drives 1 m per frame along z over `frames` frames, landmarks static.
MapState StraightDrive(int frames) {
  MotionEstimate e;
  e.range = {0, frames};
  for (int f = 0; f < frames; ++f) e.world_from_cam.push_back(Translation(0, 0, f));
  for (int l = 0; l < 8; ++l) {
    e.landmark_cluster.push_back(0);
    e.landmark_in_cluster.emplace_back(l % 3 - 1.0, l % 2 - 0.5, 5.0 + l);
  }
  MapState map;
  map.Integrate(e);
  return map;
}

TEST(RunMetrics, GroundTruthCheckComparesTheSecondEstimateWithTheTruthAndTheCamera) {
  const int frames = 20;
  PipelineResult result;
  result.map = StraightDrive(frames);
  result.frames_processed = frames;
  RunInput input;
  input.name = "straight";
  input.kind = InputKind::kKittiRaw;
  input.gt_world_from_cam.emplace();
  for (int f = 0; f < frames; ++f) {
    input.timestamps.push_back(0.1 * f);
    input.gt_world_from_cam->push_back(Translation(0, 0, f));
  }
  // The second estimate zig-zags 0.2 m either side of the true path: no similarity transform
  // takes that out, so both of its ATEs are 0.2 m, while the camera (exact) meets the truth.
  GroundTruthCrossCheck check;
  check.source = "zig-zag";
  for (int f = 0; f < frames; ++f) {
    check.positions.emplace_back(f % 2 == 0 ? 0.2 : -0.2, 0, f);
    check.position_accuracy_m.push_back(f < 11 ? 0.3 : 0.5);
  }
  input.gt_cross_check = check;

  const RunMetrics m = ComputeRunMetrics(
      input, result, BuildRunTrajectories(result.map, input.timestamps), PipelineOptions{});
  ASSERT_TRUE(m.camera.ate_sim3_m.has_value());
  EXPECT_LT(*m.camera.ate_sim3_m, 1e-9);
  EXPECT_EQ(m.ground_truth.cross_check, "zig-zag");
  ASSERT_TRUE(m.ground_truth.cross_check_ate_sim3_m.has_value());
  EXPECT_NEAR(*m.ground_truth.cross_check_ate_sim3_m, 0.2, 0.01);
  ASSERT_TRUE(m.ground_truth.camera_ate_sim3_vs_cross_check_m.has_value());
  EXPECT_NEAR(*m.ground_truth.camera_ate_sim3_vs_cross_check_m, 0.2, 0.01);
  EXPECT_NEAR(m.ground_truth.camera_sim3_scale_vs_cross_check.value_or(0), 1.0, 0.01);
  EXPECT_NEAR(m.ground_truth.cross_check_path_length_m.value_or(0), 19 * std::hypot(1.0, 0.4), 1e-6);
  EXPECT_DOUBLE_EQ(m.ground_truth.position_accuracy_median_m.value_or(0), 0.3);
  EXPECT_NE(SummarizeMetrics(m).find("ground truth check: zig-zag"), std::string::npos);
}

TEST(RunMetrics, WithoutACrossCheckTheGroundTruthBlockIsEmpty) {
  PipelineResult result;
  result.map = StraightDrive(10);
  result.frames_processed = 10;
  RunInput input;
  input.kind = InputKind::kKittiOdometry;
  input.gt_world_from_cam.emplace();
  for (int f = 0; f < 10; ++f) {
    input.timestamps.push_back(0.1 * f);
    input.gt_world_from_cam->push_back(Translation(0, 0, f));
  }
  const RunMetrics m = ComputeRunMetrics(
      input, result, BuildRunTrajectories(result.map, input.timestamps), PipelineOptions{});
  EXPECT_TRUE(m.camera.ate_m.has_value());
  EXPECT_FALSE(m.ground_truth.cross_check.has_value());
  EXPECT_FALSE(m.ground_truth.cross_check_ate_sim3_m.has_value());
}

}  // namespace
}  // namespace cslam
