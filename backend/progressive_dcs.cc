#include "backend/progressive_dcs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "backend/bundle_adjustment.h"
#include "core/logging.h"
#include "core/timer.h"

namespace cslam {

void ProgressiveDcsOptions::Check() const {
  CheckSection("estimation", [&] { estimation.Check(); });
  CheckOption(outlier_fraction > 0 && outlier_fraction < 1, "outlier_fraction", "must be in (0, 1)",
              outlier_fraction);
  CheckOption(min_outliers >= 1, "min_outliers", "must be >= 1", min_outliers);
  CheckOption(max_passes >= 1, "max_passes", "must be >= 1", max_passes);
}

void ProgressiveDcsOptions::Load(OptionsReader& reader) {
  reader.ReadSection("estimation", &estimation);
  reader.Read("outlier_fraction", &outlier_fraction);
  reader.Read("min_outliers", &min_outliers);
  reader.Read("max_passes", &max_passes);
}

BackendResult RunProgressiveDcs(const TrackletTable& table, const StereoCamera& camera,
                                FrameRange range, const ProgressiveDcsOptions& options) {
  const Timer timer;
  BackendResult result;
  result.method = "pdcs";
  MotionEstimationOptions estimation = options.estimation;
  estimation.bundle_adjustment.robust_kernel = RobustKernel::kDcs;
  estimation.shape_init.fusion_gate_chi2 = estimation.shape_init.baseline_fusion_gate_chi2;

  std::vector<int> labels(table.num_landmarks(), 0);
  std::vector<int> current;  // the set being split in this pass
  for (int i = 0; i < table.num_landmarks(); ++i) current.push_back(i);
  int label = 0;
  for (int pass = 1; pass <= options.max_passes; ++pass) {
    const Timer pass_timer;
    result.estimate = EstimateMotions(table, camera, range, labels, estimation);
    std::vector<double> error;
    EvaluateChi2(table, camera, &result.estimate, &error);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int i : current)
      if (std::isfinite(error[i])) {
        lo = std::min(lo, error[i]);
        hi = std::max(hi, error[i]);
      }
    std::vector<int> outliers;
    GetLogger("backend")->debug("pdcs pass {}: {} landmarks, mean error in [{:.3g}, {:.3g}]", pass,
                                current.size(), lo, hi);
    if (std::isfinite(lo)) {
      const double threshold = lo + options.outlier_fraction * (hi - lo);
      for (int i : current)
        if (std::isfinite(error[i]) && error[i] > threshold) outliers.push_back(i);
    }
    IterationDiagnostics diag;
    diag.iteration = pass;
    diag.num_clusters = label + 1;
    diag.chi2 = result.estimate.chi2;
    diag.estimation_ms = pass_timer.ElapsedMs();
    result.iterations.push_back(diag);
    if (static_cast<int>(outliers.size()) < options.min_outliers) break;
    if (pass == options.max_passes) {
      GetLogger("backend")->info("pdcs: stopped after {} passes with {} outliers left", pass,
                                 outliers.size());
      break;
    }
    ++label;
    for (int i : outliers) labels[i] = label;
    current = std::move(outliers);
  }
  result.time_s = timer.ElapsedS();
  return result;
}

BackendResult RunProgressiveDcs(const TrackletTable& table, const StereoCamera& camera,
                                FrameRange range, const MotionEstimationOptions& estimation) {
  ProgressiveDcsOptions options;
  options.estimation = estimation;
  return RunProgressiveDcs(table, camera, range, options);
}

}  // namespace cslam
