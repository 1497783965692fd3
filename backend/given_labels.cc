#include "backend/given_labels.h"

#include <algorithm>

#include "core/timer.h"

namespace cslam {

BackendResult RunGivenLabels(const TrackletTable& table, const StereoCamera& camera,
                             FrameRange range, const std::vector<int>& labels,
                             const MotionEstimationOptions& options) {
  const Timer timer;
  BackendResult result;
  result.method = "true-labels";
  std::vector<int> full(table.num_landmarks(), 0);
  std::copy_n(labels.begin(), std::min(labels.size(), full.size()), full.begin());
  result.estimate = EstimateMotions(table, camera, range, full, options);
  IterationDiagnostics diag;
  diag.iteration = 1;
  diag.num_clusters = 1 + static_cast<int>(result.estimate.clusters.size());
  diag.chi2 = result.estimate.chi2;
  diag.estimation_ms = timer.ElapsedMs();
  result.iterations.push_back(diag);
  result.time_s = timer.ElapsedS();
  return result;
}

}  // namespace cslam
