#include "backend/full_ba.h"

#include "core/timer.h"

namespace cslam {

BackendResult RunFullBa(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                        const MotionEstimationOptions& options) {
  const Timer timer;
  BackendResult result;
  result.method = "full-ba";
  const std::vector<int> all_static(table.num_landmarks(), 0);
  // The baseline adjusts every landmark as static (paper §5): holding the inconsistent ones
  // out would make it a robust method (camera ATE 0.003 m instead of biased, tests/backend).
  MotionEstimationOptions adjust_all = options;
  adjust_all.hold_out_inconsistent_landmarks = false;
  adjust_all.shape_init.fusion_gate_chi2 = options.shape_init.baseline_fusion_gate_chi2;
  result.estimate = EstimateMotions(table, camera, range, all_static, adjust_all);
  IterationDiagnostics diag;
  diag.iteration = 1;
  diag.num_clusters = 1;
  diag.chi2 = result.estimate.chi2;
  diag.estimation_ms = timer.ElapsedMs();
  result.iterations.push_back(diag);
  result.time_s = timer.ElapsedS();
  return result;
}

}  // namespace cslam
