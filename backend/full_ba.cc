#include "backend/full_ba.h"

#include "backend/given_labels.h"

namespace cslam {

BackendResult RunFullBa(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                        const MotionEstimationOptions& options) {
  // The baseline adjusts every landmark as static (paper §5): holding the inconsistent ones
  // out would make it a robust method (camera ATE 0.003 m instead of biased, tests/backend).
  MotionEstimationOptions adjust_all = options;
  adjust_all.hold_out_inconsistent_landmarks = false;
  adjust_all.shape_init.fusion_gate_chi2 = options.shape_init.baseline_fusion_gate_chi2;
  BackendResult result = RunGivenLabels(table, camera, range, /*labels=*/{}, adjust_all);
  result.method = "full-ba";
  return result;
}

}  // namespace cslam
