#include "system/eval/trajectory_evaluation.h"

#include <algorithm>
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

// Median over the found objects that have the figure (the mean of the middle two when even).
std::optional<double> MedianOver(const std::vector<RunMetrics::PerObject>& objects,
                                 std::optional<double> RunMetrics::PerObject::*field) {
  std::vector<double> v;
  for (const auto& o : objects)
    if (o.found && (o.*field)) v.push_back(*(o.*field));
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The distance bands of RunMetrics::Objects::distance_bands: near, middle, far.
const std::pair<double, std::optional<double>> kDistanceBands[] = {
    {0.0, 20.0}, {20.0, 40.0}, {40.0, std::nullopt}};

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
  objects.me_r_deg = MeanOver(objects.per_object, &P::me_r_deg);
  objects.me_t_m = MeanOver(objects.per_object, &P::me_t_m);
  objects.me_r_deg_median = MedianOver(objects.per_object, &P::me_r_deg);
  objects.me_t_m_median = MedianOver(objects.per_object, &P::me_t_m);
  objects.distance_bands.clear();
  for (const auto& [from, to] : kDistanceBands) {
    RunMetrics::DistanceBand band;
    band.from_m = from;
    band.to_m = to;
    std::vector<P> in_band;
    for (const auto& o : objects.per_object)
      if (o.found && o.median_distance_m && (from == 0 || *o.median_distance_m > from) &&
          (!to || *o.median_distance_m <= *to))
        in_band.push_back(o);
    band.found = static_cast<int>(in_band.size());
    band.me_r_deg = MeanOver(in_band, &P::me_r_deg);
    band.me_t_m = MeanOver(in_band, &P::me_t_m);
    band.ate_m = MeanOver(in_band, &P::ate_m);
    objects.distance_bands.push_back(band);
  }
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
