#include "system/eval/metrics_json.h"

#include <cmath>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

namespace {

using nlohmann::json;

// NaN and infinity are "unavailable" too: JSON has no spelling for them.
template <typename T>
json Value(const std::optional<T>& v) {
  if (!v) {
    return nullptr;
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(*v)) {
      return nullptr;
    }
  }
  return *v;
}

template <typename T>
void Read(const json& object, const char* key, std::optional<T>& out) {
  out.reset();
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) {
    return;
  }
  out = it->get<T>();
}

const json& Child(const json& object, const char* key) {
  static const json kEmpty = json::object();
  const auto it = object.find(key);
  return it == object.end() || it->is_null() ? kEmpty : *it;
}

}  // namespace

nlohmann::json ToJson(const RunMetrics& m) {
  json per_object = json::array();
  for (const auto& o : m.objects.per_object) {
    per_object.push_back({{"gt_object", o.gt_object},
                          {"cluster", Value(o.cluster)},
                          {"landmarks", Value(o.landmarks)},
                          {"ate_m", Value(o.ate_m)},
                          {"rpe_frame_t_m", Value(o.rpe_frame_t_m)},
                          {"rpe_frame_r_rad", Value(o.rpe_frame_r_rad)},
                          {"rpe_pairs_t_m", Value(o.rpe_pairs_t_m)},
                          {"rpe_pairs_r_rad", Value(o.rpe_pairs_r_rad)},
                          {"found", o.found}});
  }
  json j;
  j["sequence"] = m.sequence;
  j["frames"] = Value(m.frames);
  j["method"] = m.method;
  j["camera"] = {{"ate_m", Value(m.camera.ate_m)},
                 {"ate_sim3_m", Value(m.camera.ate_sim3_m)},
                 {"sim3_scale", Value(m.camera.sim3_scale)},
                 {"rpe_frame_t_m", Value(m.camera.rpe_frame_t_m)},
                 {"rpe_frame_r_rad", Value(m.camera.rpe_frame_r_rad)},
                 {"rpe_pairs_t_m", Value(m.camera.rpe_pairs_t_m)},
                 {"rpe_pairs_r_rad", Value(m.camera.rpe_pairs_r_rad)},
                 {"path_length_m", Value(m.camera.path_length_m)},
                 {"gt_path_length_m", Value(m.camera.gt_path_length_m)}};
  j["objects"] = {{"ate_m", Value(m.objects.ate_m)},
                  {"rpe_frame_t_m", Value(m.objects.rpe_frame_t_m)},
                  {"rpe_frame_r_rad", Value(m.objects.rpe_frame_r_rad)},
                  {"rpe_pairs_t_m", Value(m.objects.rpe_pairs_t_m)},
                  {"rpe_pairs_r_rad", Value(m.objects.rpe_pairs_r_rad)},
                  {"matched", Value(m.objects.matched)},
                  {"gt", Value(m.objects.gt)},
                  {"eligible", Value(m.objects.eligible)},
                  {"found_eligible", Value(m.objects.found_eligible)},
                  {"eligible_min_landmarks", Value(m.objects.eligible_min_landmarks)},
                  {"reported", Value(m.objects.reported)},
                  {"reported_on_movers", Value(m.objects.reported_on_movers)},
                  {"precision", Value(m.objects.precision)},
                  {"recall", Value(m.objects.recall)},
                  {"static_in_objects_fraction", Value(m.objects.static_in_objects_fraction)},
                  {"per_object", per_object}};
  j["clustering"] = {{"accuracy", Value(m.clustering.accuracy)},
                     {"vi", Value(m.clustering.vi)},
                     {"clusters", Value(m.clustering.clusters)},
                     {"gt_objects", Value(m.clustering.gt_objects)}};
  j["landmarks"] = {{"rmse_m", Value(m.landmarks.rmse_m)}, {"count", Value(m.landmarks.count)}};
  j["noise"] = {{"static_chi2_per_dof", Value(m.noise.static_chi2_per_dof)},
                {"static_cut_fraction", Value(m.noise.static_cut_fraction)},
                {"static_landmarks", Value(m.noise.static_landmarks)},
                {"static_observations", Value(m.noise.static_observations)}};
  j["log_chi2"] = Value(m.log_chi2);
  j["timing"] = {{"total_s", Value(m.timing.total_s)},
                 {"frontend_ms_per_frame", Value(m.timing.frontend_ms_per_frame)},
                 {"backend_ms_per_window", Value(m.timing.backend_ms_per_window)},
                 {"hz", Value(m.timing.hz)},
                 {"peak_rss_mb", Value(m.timing.peak_rss_mb)}};
  j["run"] = {{"interrupted", m.run.interrupted},
              {"windows", m.run.windows},
              {"failed_windows", m.run.failed_windows},
              {"adjustment_failed_windows", m.run.adjustment_failed_windows},
              {"tracking_lost", m.run.tracking_lost},
              {"gaps", m.run.gaps}};
  j["calibration"] = {
      {"disparity_offset_px", Value(m.calibration.disparity_offset_px)},
      {"disparity_offset_sigma_px", Value(m.calibration.disparity_offset_sigma_px)},
      {"disparity_offset_applied_px", Value(m.calibration.disparity_offset_applied_px)},
      {"disparity_offset_frames", Value(m.calibration.disparity_offset_frames)},
      {"disparity_offset_yaw_rate", Value(m.calibration.disparity_offset_yaw_rate)},
      {"disparity_offset_decision", Value(m.calibration.disparity_offset_decision)}};
  j["ground_truth"] = {
      {"cross_check", Value(m.ground_truth.cross_check)},
      {"position_accuracy_median_m", Value(m.ground_truth.position_accuracy_median_m)},
      {"cross_check_path_length_m", Value(m.ground_truth.cross_check_path_length_m)},
      {"cross_check_ate_sim3_m", Value(m.ground_truth.cross_check_ate_sim3_m)},
      {"camera_ate_sim3_vs_cross_check_m", Value(m.ground_truth.camera_ate_sim3_vs_cross_check_m)},
      {"camera_sim3_scale_vs_cross_check", Value(m.ground_truth.camera_sim3_scale_vs_cross_check)}};
  j["conventions"] = {
      {"ate",
       "RMSE of translation after SE(3) Umeyama alignment (ate_sim3_m: Sim(3)); objects each "
       "aligned on their own"},
      {"rpe_frame",
       "RMSE over consecutive frames (delta 1), E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j), evo_rpe default"},
      {"rpe_pairs",
       "RMSE over all ordered pairs i != j, randomly subsampled to 10000 (mt19937 seed 42)"},
      {"vi", "natural logarithm (nats)"},
      {"accuracy", "Hungarian matching on the contingency table / all landmarks"}};
  return j;
}

RunMetrics RunMetricsFromJson(const nlohmann::json& j, const std::string& source) {
  RunMetrics m;
  try {
    if (!j.is_object()) {
      throw InputError(source, "expected a JSON object");
    }
    if (j.contains("sequence") && j["sequence"].is_string()) {
      m.sequence = j["sequence"].get<std::string>();
    }
    if (j.contains("method") && j["method"].is_string()) {
      m.method = j["method"].get<std::string>();
    }
    Read(j, "frames", m.frames);
    const json& c = Child(j, "camera");
    Read(c, "ate_m", m.camera.ate_m);
    Read(c, "ate_sim3_m", m.camera.ate_sim3_m);
    Read(c, "sim3_scale", m.camera.sim3_scale);
    Read(c, "rpe_frame_t_m", m.camera.rpe_frame_t_m);
    Read(c, "rpe_frame_r_rad", m.camera.rpe_frame_r_rad);
    Read(c, "rpe_pairs_t_m", m.camera.rpe_pairs_t_m);
    Read(c, "rpe_pairs_r_rad", m.camera.rpe_pairs_r_rad);
    Read(c, "path_length_m", m.camera.path_length_m);
    Read(c, "gt_path_length_m", m.camera.gt_path_length_m);
    const json& o = Child(j, "objects");
    Read(o, "ate_m", m.objects.ate_m);
    Read(o, "rpe_frame_t_m", m.objects.rpe_frame_t_m);
    Read(o, "rpe_frame_r_rad", m.objects.rpe_frame_r_rad);
    Read(o, "rpe_pairs_t_m", m.objects.rpe_pairs_t_m);
    Read(o, "rpe_pairs_r_rad", m.objects.rpe_pairs_r_rad);
    Read(o, "matched", m.objects.matched);
    Read(o, "gt", m.objects.gt);
    Read(o, "eligible", m.objects.eligible);
    Read(o, "found_eligible", m.objects.found_eligible);
    Read(o, "eligible_min_landmarks", m.objects.eligible_min_landmarks);
    Read(o, "reported", m.objects.reported);
    Read(o, "reported_on_movers", m.objects.reported_on_movers);
    Read(o, "precision", m.objects.precision);
    Read(o, "recall", m.objects.recall);
    Read(o, "static_in_objects_fraction", m.objects.static_in_objects_fraction);
    if (o.contains("per_object") && o["per_object"].is_array()) {
      for (const json& e : o["per_object"]) {
        RunMetrics::PerObject p;
        if (e.contains("gt_object") && !e["gt_object"].is_null()) {
          p.gt_object = e["gt_object"].get<int>();
        }
        Read(e, "cluster", p.cluster);
        Read(e, "landmarks", p.landmarks);
        Read(e, "ate_m", p.ate_m);
        Read(e, "rpe_frame_t_m", p.rpe_frame_t_m);
        Read(e, "rpe_frame_r_rad", p.rpe_frame_r_rad);
        Read(e, "rpe_pairs_t_m", p.rpe_pairs_t_m);
        Read(e, "rpe_pairs_r_rad", p.rpe_pairs_r_rad);
        p.found = e.value("found", false);
        m.objects.per_object.push_back(p);
      }
    }
    const json& cl = Child(j, "clustering");
    Read(cl, "accuracy", m.clustering.accuracy);
    Read(cl, "vi", m.clustering.vi);
    Read(cl, "clusters", m.clustering.clusters);
    Read(cl, "gt_objects", m.clustering.gt_objects);
    const json& l = Child(j, "landmarks");
    Read(l, "rmse_m", m.landmarks.rmse_m);
    Read(l, "count", m.landmarks.count);
    const json& nz = Child(j, "noise");
    Read(nz, "static_chi2_per_dof", m.noise.static_chi2_per_dof);
    Read(nz, "static_cut_fraction", m.noise.static_cut_fraction);
    Read(nz, "static_landmarks", m.noise.static_landmarks);
    Read(nz, "static_observations", m.noise.static_observations);
    Read(j, "log_chi2", m.log_chi2);
    const json& t = Child(j, "timing");
    Read(t, "total_s", m.timing.total_s);
    Read(t, "frontend_ms_per_frame", m.timing.frontend_ms_per_frame);
    Read(t, "backend_ms_per_window", m.timing.backend_ms_per_window);
    Read(t, "hz", m.timing.hz);
    Read(t, "peak_rss_mb", m.timing.peak_rss_mb);
    const json& r = Child(j, "run");
    if (r.is_object()) {
      m.run.interrupted = r.value("interrupted", false);
      m.run.windows = r.value("windows", 0);
      m.run.failed_windows = r.value("failed_windows", std::vector<int>{});
      m.run.adjustment_failed_windows = r.value("adjustment_failed_windows", std::vector<int>{});
      m.run.tracking_lost = r.value("tracking_lost", std::vector<int>{});
      m.run.gaps = r.value("gaps", std::vector<int>{});
    }
    const json& ca = Child(j, "calibration");
    Read(ca, "disparity_offset_px", m.calibration.disparity_offset_px);
    Read(ca, "disparity_offset_sigma_px", m.calibration.disparity_offset_sigma_px);
    Read(ca, "disparity_offset_applied_px", m.calibration.disparity_offset_applied_px);
    Read(ca, "disparity_offset_frames", m.calibration.disparity_offset_frames);
    Read(ca, "disparity_offset_yaw_rate", m.calibration.disparity_offset_yaw_rate);
    Read(ca, "disparity_offset_decision", m.calibration.disparity_offset_decision);
    const json& g = Child(j, "ground_truth");
    Read(g, "cross_check", m.ground_truth.cross_check);
    Read(g, "position_accuracy_median_m", m.ground_truth.position_accuracy_median_m);
    Read(g, "cross_check_path_length_m", m.ground_truth.cross_check_path_length_m);
    Read(g, "cross_check_ate_sim3_m", m.ground_truth.cross_check_ate_sim3_m);
    Read(g, "camera_ate_sim3_vs_cross_check_m", m.ground_truth.camera_ate_sim3_vs_cross_check_m);
    Read(g, "camera_sim3_scale_vs_cross_check", m.ground_truth.camera_sim3_scale_vs_cross_check);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source, std::string("unexpected value type: ") + e.what());
  }
  return m;
}

void WriteMetricsJson(const RunMetrics& metrics, const std::string& path) {
  const std::string text = ToJson(metrics).dump(2);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << '\n'; });
}

}  // namespace cslam
