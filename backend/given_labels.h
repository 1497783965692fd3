#pragma once
// The reference "true labels" (not in the paper): ClusterSLAM's motion estimation with the
// labels handed in instead of clustered. Given the ground truth it is the best the
// clustering can do for the camera and the objects with this estimator, so it separates
// what the clustering costs from what the estimation itself reaches.
#include <vector>

#include "backend/backend_result.h"
#include "backend/motion_estimation.h"

namespace cslam {

/// One EstimateMotions over `range` with `labels` ([landmark id] → cluster, 0 = static;
/// landmarks past the end of `labels` count as static). method = "true-labels".
BackendResult RunGivenLabels(const TrackletTable& table, const StereoCamera& camera,
                             FrameRange range, const std::vector<int>& labels,
                             const MotionEstimationOptions& options);

}  // namespace cslam
