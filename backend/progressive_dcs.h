#pragma once
// Baseline "Progressive DCS" (clusterslam_spec.md §8.2, paper §4.2): bundle adjustment with
// the DCS kernel; the landmarks of the current set whose mean reprojection error exceeds
// χ²_N + 0.3 (χ²_M − χ²_N) (smallest / largest per-landmark error of the set) become the next
// object, solved as one rigid body in the next pass; stop when fewer than 10 remain.
#include "backend/backend_result.h"
#include "backend/motion_estimation.h"
#include "core/options_reader.h"

namespace cslam {

/// Parameters of Progressive DCS.
struct ProgressiveDcsOptions {
  /// Estimation of every pass; the bundle adjustment's kernel is forced to DCS.
  MotionEstimationOptions estimation;  ///< section "estimation"
  /// Position of the outlier threshold between the smallest and largest error [paper: 0.3].
  double outlier_fraction = 0.3;
  /// Fewer outliers than this end the segmentation [paper: 10].
  int min_outliers = 10;
  /// Upper bound on passes (objects + 1) [ours: guards against endless splitting].
  int max_passes = 10;

  /// Throws ConfigError naming the field that breaks its rule.
  void Check() const;
  /// Reads every field by its snake_case name.
  void Load(OptionsReader& reader);
};

/// Runs Progressive DCS over `range`; method = "pdcs". Pass k's inliers keep label k (0 =
/// static); the final estimate is EstimateMotions on the final labelling.
BackendResult RunProgressiveDcs(const TrackletTable& table, const StereoCamera& camera,
                                FrameRange range, const ProgressiveDcsOptions& options);
/// The same with the paper's splitting parameters and `estimation` for every pass.
BackendResult RunProgressiveDcs(const TrackletTable& table, const StereoCamera& camera,
                                FrameRange range, const MotionEstimationOptions& estimation);

}  // namespace cslam
