#pragma once
// The metrics.json trajectory sections filled from trajectories, shared by `cslam eval`,
// `cslam run` and the benchmarks so every caller reports the same protocol.
#include "system/eval/metrics_json.h"
#include "system/eval/trajectory.h"
#include "system/eval/trajectory_metrics.h"

namespace cslam {

/// `v`, or empty when it is NaN or infinite (metrics.json has no spelling for those).
std::optional<double> Finite(double v);

/// Camera section: ATE (SE(3) and Sim(3) with its scale), RPE per frame (delta 1) and all
/// pairs (≤ 10 000, seed 42), both path lengths. Figures that cannot be computed (too few
/// associated poses) stay empty.
RunMetrics::Camera EvaluateCameraTrajectory(const Trajectory& gt, const Trajectory& est,
                                            const AssociationOptions& association = {});

/// One object's figures: its trajectory aligned on its own (SE(3) and Sim(3) ATE), RPE per frame
/// and all pairs; camera_frame_rmse_m is left to the caller, which has the cameras. Sets `found` = true; gt_object, cluster and landmarks are left to the caller.
RunMetrics::PerObject EvaluateObjectTrajectory(const Trajectory& gt, const Trajectory& est,
                                               const AssociationOptions& association = {});

/// Objects with fewer clusterable landmarks than this are left out of `objects.eligible`.
inline constexpr int kEligibleObjectLandmarks = 30;

/// Fills the averages of `objects` (ate_m, ate_sim3_m, camera_frame_rmse_m, rpe_*) over its found per_object entries that have
/// the figure, `matched` = number found, `gt` = number of entries, `eligible` = entries with
/// `landmarks` ≥ `min_landmarks` and `found_eligible` = how many of those were found.
void SummariseObjects(RunMetrics::Objects& objects,
                      int min_landmarks = kEligibleObjectLandmarks);

}  // namespace cslam
