#pragma once
// Baseline "Full BA" (clusterslam_spec.md §8.1): bundle adjustment with every landmark static.
#include "backend/backend_result.h"
#include "backend/motion_estimation.h"

namespace cslam {

/// Every landmark observed in `range` is labelled static (0) and EstimateMotions runs once
/// (shape initialisation of the one cluster, then bundle adjustment with `options`' kernel).
/// method = "full-ba".
BackendResult RunFullBa(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                        const MotionEstimationOptions& options);

}  // namespace cslam
