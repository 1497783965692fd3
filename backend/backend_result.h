#pragma once
// What every backend method (ClusterSLAM, Full BA, Progressive DCS) returns.
#include <string>
#include <vector>

#include "backend/motion_estimation.h"

namespace cslam {

/// One outer-loop iteration of Algorithm 1 (spec §2), for logs and the benchmark tables.
struct IterationDiagnostics {
  int iteration = 0;
  int num_clusters = 0;          ///< after consensus and the minimum-size rule
  double vi_to_previous = 0.0;   ///< variation of information to the previous labelling
  double chi2 = 0.0;
  int reassigned = 0;            ///< model assignment [ours]: landmarks moved to another model
  int outliers = 0;              ///< model assignment: landmarks no model explained (re-clustered)
  int merges = 0;                ///< model assignment: clusters merged into another
  double clustering_ms = 0.0;    ///< motion distance + HAC + consensus (or model assignment)
  double estimation_ms = 0.0;    ///< shape initialisation + bundle adjustment
};

/// Result of one backend run over a frame range.
struct BackendResult {
  std::string method;            ///< "clusterslam", "full-ba", "pdcs"
  MotionEstimate estimate;
  std::vector<IterationDiagnostics> iterations;
  double time_s = 0.0;           ///< wall time of the whole backend call
  /// ClusterSLAM online windows: started from the map's prior (RunClusterSlamWindow) rather
  /// than from scratch.
  bool warm_started = false;
};

}  // namespace cslam
