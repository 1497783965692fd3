#include "system/eval/metrics_json.h"

#include "core/atomic_file.h"

namespace cslam {

nlohmann::json ToJson(const RunMetrics& m) {
  nlohmann::json j = FieldsToJson(m);
  j["conventions"] = {
      {"ate",
       "RMSE of translation after SE(3) Umeyama alignment (ate_sim3_m: Sim(3)); objects each "
       "aligned on their own"},
      {"rpe_frame",
       "RMSE over consecutive frames (delta 1), E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j), evo_rpe default"},
      {"rpe_pairs",
       "RMSE over all ordered pairs i != j, randomly subsampled to 10000 (mt19937 seed 42)"},
      {"me",
       "objects' motion error per frame: H = X_k X_(k-1)^-1 taken in the camera frame at k-1, "
       "me_r = angle(R_gt^T R_est) in degrees, me_t = |H_est c - H_gt c| at the true centre c, "
       "means over consecutive tracked frames; distance bands by the median true distance"},
      {"vi", "natural logarithm (nats)"},
      {"accuracy", "Hungarian matching on the contingency table / all landmarks"}};
  return j;
}

RunMetrics RunMetricsFromJson(const nlohmann::json& j, const std::string& source) {
  RunMetrics m;
  FieldsFromJson(j, m, source);
  return m;
}

void WriteMetricsJson(const RunMetrics& metrics, const std::string& path) {
  const std::string text = ToJson(metrics).dump(2);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << '\n'; });
}

}  // namespace cslam
