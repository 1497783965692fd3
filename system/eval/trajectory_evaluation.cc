#include "system/eval/trajectory_evaluation.h"

#include <cmath>

namespace cslam {

std::optional<double> Finite(double v) {
  if (!std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

namespace {

// Mean over the found objects that have the figure.
std::optional<double> MeanOver(const std::vector<RunMetrics::PerObject>& objects,
                               std::optional<double> RunMetrics::PerObject::*field) {
  double sum = 0;
  int n = 0;
  for (const auto& o : objects) {
    if (!o.found || !(o.*field)) {
      continue;
    }
    sum += *(o.*field);
    ++n;
  }
  if (n == 0) {
    return std::nullopt;
  }
  return sum / n;
}

}  // namespace

RunMetrics::Camera EvaluateCameraTrajectory(const Trajectory& gt, const Trajectory& est,
                                            const AssociationOptions& association) {
  RunMetrics::Camera c;
  const AteResult se3 = ComputeAte(gt, est, false, association);
  const AteResult sim3 = ComputeAte(gt, est, true, association);
  c.ate_m = Finite(se3.rmse_m);
  c.ate_sim3_m = Finite(sim3.rmse_m);
  if (c.ate_sim3_m) {
    c.sim3_scale = sim3.alignment.scale;
  }
  const RpeResult frame = ComputeRpePerFrame(gt, est, 1, association);
  c.rpe_frame_t_m = Finite(frame.trans_rmse_m);
  c.rpe_frame_r_rad = Finite(frame.rot_rmse_rad);
  const RpeResult pairs = ComputeRpeAllPairs(gt, est, 10000, 42, association);
  c.rpe_pairs_t_m = Finite(pairs.trans_rmse_m);
  c.rpe_pairs_r_rad = Finite(pairs.rot_rmse_rad);
  c.path_length_m = PathLength(est);
  c.gt_path_length_m = PathLength(gt);
  return c;
}

RunMetrics::PerObject EvaluateObjectTrajectory(const Trajectory& gt, const Trajectory& est,
                                               const AssociationOptions& association) {
  RunMetrics::PerObject o;
  o.found = true;
  o.ate_m = Finite(ComputeAte(gt, est, false, association).rmse_m);
  o.ate_sim3_m = Finite(ComputeAte(gt, est, true, association).rmse_m);
  const RpeResult frame = ComputeRpePerFrame(gt, est, 1, association);
  o.rpe_frame_t_m = Finite(frame.trans_rmse_m);
  o.rpe_frame_r_rad = Finite(frame.rot_rmse_rad);
  const RpeResult pairs = ComputeRpeAllPairs(gt, est, 10000, 42, association);
  o.rpe_pairs_t_m = Finite(pairs.trans_rmse_m);
  o.rpe_pairs_r_rad = Finite(pairs.rot_rmse_rad);
  return o;
}

void SummariseObjects(RunMetrics::Objects& objects, int min_landmarks) {
  using P = RunMetrics::PerObject;
  objects.ate_m = MeanOver(objects.per_object, &P::ate_m);
  objects.ate_sim3_m = MeanOver(objects.per_object, &P::ate_sim3_m);
  objects.camera_frame_rmse_m = MeanOver(objects.per_object, &P::camera_frame_rmse_m);
  objects.rpe_frame_t_m = MeanOver(objects.per_object, &P::rpe_frame_t_m);
  objects.rpe_frame_r_rad = MeanOver(objects.per_object, &P::rpe_frame_r_rad);
  objects.rpe_pairs_t_m = MeanOver(objects.per_object, &P::rpe_pairs_t_m);
  objects.rpe_pairs_r_rad = MeanOver(objects.per_object, &P::rpe_pairs_r_rad);
  int matched = 0, eligible = 0, found_eligible = 0;
  for (const auto& o : objects.per_object) {
    matched += o.found ? 1 : 0;
    if (o.landmarks.value_or(0) >= min_landmarks) {
      ++eligible;
      found_eligible += o.found ? 1 : 0;
    }
  }
  objects.matched = matched;
  objects.eligible = eligible;
  objects.found_eligible = found_eligible;
  objects.eligible_min_landmarks = min_landmarks;
  objects.gt = int(objects.per_object.size());
}

}  // namespace cslam
