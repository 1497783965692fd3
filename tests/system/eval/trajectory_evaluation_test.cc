#include "system/eval/trajectory_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

namespace cslam {
namespace {

Trajectory Line(int n, double step_m) {
  Trajectory t;
  for (int k = 0; k < n; ++k) {
    Pose p = Pose::Identity();
    p.linear() = ExpSO3(Eigen::Vector3d(0, 0.02 * k, 0));
    p.translation() = Eigen::Vector3d(std::sin(0.05 * k), 0, step_m * k);
    t.poses.push_back(p);
    t.frames.push_back(k);
  }
  return t;
}

TEST(TrajectoryEvaluation, CameraSectionOfAMovedCopyIsExact) {
  const Trajectory gt = Line(40, 1.0);
  Trajectory est = gt;
  Vector6d xi;
  xi << 0.1, 0.7, -0.2, 5, 1, -2;
  for (Pose& p : est.poses) p = PoseFromVector(xi) * p;
  const RunMetrics::Camera c = EvaluateCameraTrajectory(gt, est);
  ASSERT_TRUE(c.ate_m && c.ate_sim3_m && c.sim3_scale && c.rpe_frame_t_m && c.rpe_pairs_t_m);
  EXPECT_LT(*c.ate_m, 1e-9);
  EXPECT_LT(*c.ate_sim3_m, 1e-9);
  EXPECT_NEAR(*c.sim3_scale, 1.0, 1e-9);
  EXPECT_LT(*c.rpe_frame_t_m, 1e-9);
  EXPECT_LT(*c.rpe_frame_r_rad, 1e-9);
  EXPECT_LT(*c.rpe_pairs_t_m, 1e-8);
  EXPECT_NEAR(*c.path_length_m, *c.gt_path_length_m, 1e-9);
}

TEST(TrajectoryEvaluation, TooShortLeavesFiguresEmpty) {
  const Trajectory gt = Line(2, 1.0);
  const RunMetrics::Camera c = EvaluateCameraTrajectory(gt, gt);
  EXPECT_FALSE(c.ate_m.has_value());
  EXPECT_FALSE(c.sim3_scale.has_value());
  EXPECT_TRUE(c.rpe_frame_t_m.has_value());  // one pair is enough for RPE
}

TEST(TrajectoryEvaluation, ObjectsAverageOverFoundOnes) {
  // Object trajectories have arbitrary origins: each is aligned on its own.
  const Trajectory gt = Line(20, 0.5);
  Trajectory est = gt;
  for (Pose& p : est.poses) p.translation() += Eigen::Vector3d(100, -50, 3);
  RunMetrics::Objects objects;
  objects.per_object.push_back(EvaluateObjectTrajectory(gt, est));
  objects.per_object.back().ate_m = 0.2;  // pretend a second figure to average
  objects.per_object.push_back(EvaluateObjectTrajectory(gt, est));
  RunMetrics::PerObject missed;
  missed.gt_object = 9;
  missed.ate_m = 100.0;  // not found: must not enter the average
  objects.per_object.push_back(missed);
  EXPECT_LT(*objects.per_object[1].ate_m, 1e-9);
  SummariseObjects(objects);
  EXPECT_EQ(objects.matched, 2);
  EXPECT_EQ(objects.gt, 3);
  EXPECT_NEAR(*objects.ate_m, 0.1, 1e-9);
  EXPECT_LT(*objects.ate_sim3_m, 1e-9);
  EXPECT_LT(*objects.rpe_frame_t_m, 1e-9);
}

TEST(TrajectoryEvaluation, AnObjectsSim3AteTakesOutAScaleErrorItsSe3AteKeeps) {
  // A camera whose scale is 4 % off places every object's track 4 % too long as well.
  const Trajectory gt = Line(60, 0.5);
  Trajectory est = gt;
  for (Pose& p : est.poses) p.translation() *= 1.04;
  const RunMetrics::PerObject o = EvaluateObjectTrajectory(gt, est);
  ASSERT_TRUE(o.ate_m && o.ate_sim3_m);
  EXPECT_LT(*o.ate_sim3_m, 1e-9);
  EXPECT_GT(*o.ate_m, 0.1);
  EXPECT_FALSE(o.camera_frame_rmse_m.has_value());  // the caller's, who has the cameras
}

TEST(TrajectoryEvaluation, EligibleObjectsAreThoseWithEnoughLandmarks) {
  // found with 30 / missed with 30 / found with 29 / missed with 5 / missed, count unknown
  RunMetrics::Objects objects;
  const std::vector<std::pair<int, bool>> entries = {{30, true}, {30, false}, {29, true}, {5, false}};
  for (const auto& [landmarks, found] : entries) {
    RunMetrics::PerObject o;
    o.landmarks = landmarks;
    o.found = found;
    objects.per_object.push_back(o);
  }
  objects.per_object.emplace_back();
  SummariseObjects(objects);
  EXPECT_EQ(objects.gt, 5);
  EXPECT_EQ(objects.matched, 2);
  EXPECT_EQ(objects.eligible_min_landmarks, kEligibleObjectLandmarks);
  EXPECT_EQ(objects.eligible, 2);        // exactly 30 counts, 29 does not
  EXPECT_EQ(objects.found_eligible, 1);  // the missed 30-landmark object stays missed
  SummariseObjects(objects, 5);
  EXPECT_EQ(objects.eligible, 4);
  EXPECT_EQ(objects.found_eligible, 2);
  EXPECT_EQ(objects.eligible_min_landmarks, 5);
}

}  // namespace
}  // namespace cslam

namespace cslam {
namespace {

TEST(TrajectoryEvaluation, MotionErrorsAreAveragedOverFoundObjectsAndSplitByTheirDistance) {
  RunMetrics::Objects objects;
  // (median distance, ME_r, ME_t, found): 20 m belongs to the near band, 40 m to the middle.
  const std::tuple<double, double, double, bool> rows[] = {
      {10, 0.2, 0.05, true}, {20, 0.4, 0.07, true}, {25, 1.0, 0.2, true},
      {40, 3.0, 0.4, true},  {55, 9.0, 1.0, true},  {15, 50.0, 5.0, false}};
  for (const auto& [d, r, t, found] : rows) {
    RunMetrics::PerObject o;
    o.found = found;
    o.median_distance_m = d;
    o.me_r_deg = r;
    o.me_t_m = t;
    o.ate_m = 2 * t;
    objects.per_object.push_back(o);
  }
  SummariseObjects(objects);
  EXPECT_NEAR(*objects.me_r_deg, (0.2 + 0.4 + 1.0 + 3.0 + 9.0) / 5, 1e-12);
  EXPECT_NEAR(*objects.me_t_m, (0.05 + 0.07 + 0.2 + 0.4 + 1.0) / 5, 1e-12);
  EXPECT_NEAR(*objects.me_r_deg_median, 1.0, 1e-12);
  EXPECT_NEAR(*objects.me_t_m_median, 0.2, 1e-12);
  ASSERT_EQ(objects.distance_bands.size(), 3u);
  const auto& near = objects.distance_bands[0];
  const auto& middle = objects.distance_bands[1];
  const auto& far = objects.distance_bands[2];
  EXPECT_EQ(near.found, 2);
  EXPECT_NEAR(*near.me_r_deg, 0.3, 1e-12);
  EXPECT_NEAR(*near.ate_m, 0.12, 1e-12);
  EXPECT_EQ(middle.found, 2);
  EXPECT_NEAR(*middle.me_t_m, 0.3, 1e-12);
  EXPECT_EQ(far.found, 1);
  EXPECT_FALSE(far.to_m.has_value());
  EXPECT_NEAR(*far.me_r_deg, 9.0, 1e-12);
}

}  // namespace
}  // namespace cslam
