#include "system/run/run_metrics.h"

#include <gtest/gtest.h>

#include "core/rigid.h"
#include "tests/support/cameras.h"
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

TEST(RunMetrics, AfterAStopTheGroundTruthPathLengthCoversOnlyTheFramesWithAnEstimate) {
  // Stopped with 30 frames read and 20 estimated (the last window never ran): the summary's
  // "gt" path length must be that of frames 0..19 (19 m), not of all 30 read (29 m).
  PipelineResult result;
  result.map = StraightDrive(20);
  result.frames_processed = 30;
  result.interrupted = true;
  RunInput input;
  input.name = "stopped";
  input.gt_world_from_cam.emplace();
  for (int f = 0; f < 40; ++f) {
    input.timestamps.push_back(0.1 * f);
    input.gt_world_from_cam->push_back(Translation(0, 0, f));
  }
  const RunMetrics m = ComputeRunMetrics(
      input, result, BuildRunTrajectories(result.map, input.timestamps), PipelineOptions{});
  EXPECT_NEAR(m.camera.path_length_m.value_or(0), 19.0, 1e-9);
  EXPECT_NEAR(m.camera.gt_path_length_m.value_or(0), 19.0, 1e-9);
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

TEST(RunMetrics, AVanOnAKittiDriveIsMeasuredAgainstItsBoxInTheCameraAsWellAsInTheWorld) {
  // The estimated camera runs 5 % long (the size of raw 0005's disagreement between the GPS and
  // the estimate) and drifts sideways, but places a turning van exactly relative to itself: the
  // van's world ATE
  // carries the camera's error, its camera-frame error is zero although the estimate tracks the
  // centroid of points on the van's rear, not its box's centre.
  const int frames = 30;
  const StereoCamera camera = testing::KittiSizedCamera();
  RunInput input;
  input.kind = InputKind::kKittiRaw;
  input.camera = camera;
  input.gt_world_from_cam.emplace();
  input.gt_boxes.resize(frames);
  MotionEstimate e;
  e.range = {0, frames};
  ClusterMotion van;
  van.cluster = 1;
  const Eigen::Matrix3d box_up_is_camera_up = ExpSO3(Eigen::Vector3d(M_PI / 2, 0, 0));
  for (int f = 0; f < frames; ++f) {
    input.timestamps.push_back(0.1 * f);
    input.gt_world_from_cam->push_back(testing::Translation(0, 0, 2.0 * f));
    e.world_from_cam.push_back(testing::Translation(0.004 * f * f, 0, 2.1 * f));
    ObjectBox box;
    box.track_id = 0;
    box.type = "Van";
    box.l = 4.4;
    box.w = 1.9;
    box.h = 2.0;
    box.cam_from_box.linear() = ExpSO3(Eigen::Vector3d(0, -0.03 * f, 0)) * box_up_is_camera_up;
    box.cam_from_box.translation() = Eigen::Vector3d(2.0 + 0.1 * f, 1.6, 14.0 + 0.2 * f);
    input.gt_boxes[f].push_back(box);
    van.frames.push_back(f);
    van.cam_from_cluster.push_back(box.cam_from_box);  // the cluster frame is the box frame
    van.world_from_cluster.push_back(e.world_from_cam.back() * box.cam_from_box);
  }
  e.clusters.push_back(van);
  // Static points beside the road and points on the van's rear face (box frame: x forward).
  std::vector<Eigen::Vector3d> on_van;
  for (int i = 0; i < 8; ++i) on_van.emplace_back(-2.1, -0.8 + 0.2 * i, 0.3 + 0.2 * i);
  PipelineResult result;
  for (int l = 0; l < 16; ++l) {
    const bool moving = l >= 8;
    const Eigen::Vector3d in_cluster =
        moving ? on_van[l - 8] : Eigen::Vector3d(l % 2 == 0 ? -6.0 : 6.0, 1.0, 8.0 + 8 * l);
    e.landmark_cluster.push_back(moving ? 1 : 0);
    e.landmark_in_cluster.push_back(in_cluster);
    result.table.NewLandmark();
    for (int f = 0; f < frames; ++f) {
      const Eigen::Vector3d in_cam = moving ? Eigen::Vector3d(van.cam_from_cluster[f] * in_cluster)
                                            : Eigen::Vector3d(in_cluster - Eigen::Vector3d(0, 0, 2.0 * f));
      Eigen::Vector3d x;
      if (in_cam.z() > 1.0 && camera.Project(in_cam, &x))
        result.table.Add(l, f, x, Eigen::Matrix3d::Identity());
    }
  }
  result.map.Integrate(e);
  result.frames_processed = frames;
  ASSERT_EQ(result.map.ClusterOf(8), 1);

  const RunMetrics m = ComputeRunMetrics(
      input, result, BuildRunTrajectories(result.map, input.timestamps), PipelineOptions{});
  ASSERT_EQ(m.objects.per_object.size(), 1u);
  const RunMetrics::PerObject& o = m.objects.per_object[0];
  ASSERT_TRUE(o.found);
  ASSERT_TRUE(o.ate_m && o.ate_sim3_m && o.camera_frame_rmse_m);
  EXPECT_GT(*o.ate_m, 0.2);
  EXPECT_LT(*o.camera_frame_rmse_m, 1e-6);
  EXPECT_LT(*m.objects.camera_frame_rmse_m, 1e-6);
}

}  // namespace
}  // namespace cslam
