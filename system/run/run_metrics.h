#pragma once
// metrics.json of a run, computed against whatever ground truth the input carries:
// camera ATE/RPE (any dataset with poses); clustering accuracy, VI, landmark RMSE and object
// trajectory errors (synthetic); moving labelled objects matched to clusters through the
// landmarks inside their boxes (KITTI raw).
#include "system/eval/metrics_json.h"
#include "system/pipeline/pipeline.h"
#include "system/pipeline/run_input.h"
#include "system/run/run_trajectories.h"

namespace cslam {

/// Metrics of a finished run, its trajectories evaluated as given (BuildRunTrajectories of its
/// map); fields without ground truth stay unset (null in JSON).
RunMetrics ComputeRunMetrics(const RunInput& input, const PipelineResult& result,
                             const RunTrajectories& trajectories, const PipelineOptions& options);

/// One-paragraph human summary of the metrics (printed by `cslam run` and `cslam demo`).
std::string SummarizeMetrics(const RunMetrics& metrics);

}  // namespace cslam
