#include "system/eval/metrics_json.h"

#include <cmath>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

namespace {

using nlohmann::json;

// Each section's fields, listed once: ToJson writes them and RunMetricsFromJson reads them by
// walking the same list, so a new metric is one line in one list. `f(key, member)`.
constexpr auto kCameraFields = [](auto& c, auto&& f) {
  f("ate_m", c.ate_m);
  f("ate_sim3_m", c.ate_sim3_m);
  f("sim3_scale", c.sim3_scale);
  f("rpe_frame_t_m", c.rpe_frame_t_m);
  f("rpe_frame_r_rad", c.rpe_frame_r_rad);
  f("rpe_pairs_t_m", c.rpe_pairs_t_m);
  f("rpe_pairs_r_rad", c.rpe_pairs_r_rad);
  f("path_length_m", c.path_length_m);
  f("gt_path_length_m", c.gt_path_length_m);
};
constexpr auto kPerObjectFields = [](auto& o, auto&& f) {
  f("gt_object", o.gt_object);
  f("cluster", o.cluster);
  f("landmarks", o.landmarks);
  f("ate_m", o.ate_m);
  f("rpe_frame_t_m", o.rpe_frame_t_m);
  f("rpe_frame_r_rad", o.rpe_frame_r_rad);
  f("rpe_pairs_t_m", o.rpe_pairs_t_m);
  f("rpe_pairs_r_rad", o.rpe_pairs_r_rad);
  f("found", o.found);
};
constexpr auto kObjectFields = [](auto& o, auto&& f) {
  f("ate_m", o.ate_m);
  f("rpe_frame_t_m", o.rpe_frame_t_m);
  f("rpe_frame_r_rad", o.rpe_frame_r_rad);
  f("rpe_pairs_t_m", o.rpe_pairs_t_m);
  f("rpe_pairs_r_rad", o.rpe_pairs_r_rad);
  f("matched", o.matched);
  f("gt", o.gt);
  f("eligible", o.eligible);
  f("found_eligible", o.found_eligible);
  f("eligible_min_landmarks", o.eligible_min_landmarks);
  f("reported", o.reported);
  f("reported_on_movers", o.reported_on_movers);
  f("precision", o.precision);
  f("recall", o.recall);
  f("static_in_objects_fraction", o.static_in_objects_fraction);
  f("per_object", o.per_object);
};
constexpr auto kClusteringFields = [](auto& c, auto&& f) {
  f("accuracy", c.accuracy);
  f("vi", c.vi);
  f("clusters", c.clusters);
  f("gt_objects", c.gt_objects);
};
constexpr auto kLandmarkFields = [](auto& l, auto&& f) {
  f("rmse_m", l.rmse_m);
  f("count", l.count);
};
constexpr auto kNoiseFields = [](auto& n, auto&& f) {
  f("static_chi2_per_dof", n.static_chi2_per_dof);
  f("static_cut_fraction", n.static_cut_fraction);
  f("static_landmarks", n.static_landmarks);
  f("static_observations", n.static_observations);
};
constexpr auto kTimingFields = [](auto& t, auto&& f) {
  f("total_s", t.total_s);
  f("frontend_ms_per_frame", t.frontend_ms_per_frame);
  f("backend_ms_per_window", t.backend_ms_per_window);
  f("hz", t.hz);
  f("peak_rss_mb", t.peak_rss_mb);
};
constexpr auto kRunFields = [](auto& r, auto&& f) {
  f("interrupted", r.interrupted);
  f("windows", r.windows);
  f("failed_windows", r.failed_windows);
  f("adjustment_failed_windows", r.adjustment_failed_windows);
  f("tracking_lost", r.tracking_lost);
  f("gaps", r.gaps);
};
constexpr auto kCalibrationFields = [](auto& c, auto&& f) {
  f("disparity_offset_px", c.disparity_offset_px);
  f("disparity_offset_sigma_px", c.disparity_offset_sigma_px);
  f("disparity_offset_applied_px", c.disparity_offset_applied_px);
  f("disparity_offset_frames", c.disparity_offset_frames);
  f("disparity_offset_yaw_rate", c.disparity_offset_yaw_rate);
  f("disparity_offset_decision", c.disparity_offset_decision);
};
constexpr auto kGroundTruthFields = [](auto& g, auto&& f) {
  f("cross_check", g.cross_check);
  f("position_accuracy_median_m", g.position_accuracy_median_m);
  f("cross_check_path_length_m", g.cross_check_path_length_m);
  f("cross_check_ate_sim3_m", g.cross_check_ate_sim3_m);
  f("camera_ate_sim3_vs_cross_check_m", g.camera_ate_sim3_vs_cross_check_m);
  f("camera_sim3_scale_vs_cross_check", g.camera_sim3_scale_vs_cross_check);
};
// The top level: plain fields, and sections (JSON objects) with their field lists.
constexpr auto kRunMetricsFields = [](auto& m, auto&& f, auto&& section) {
  f("sequence", m.sequence);
  f("frames", m.frames);
  f("method", m.method);
  section("camera", m.camera, kCameraFields);
  section("objects", m.objects, kObjectFields);
  section("clustering", m.clustering, kClusteringFields);
  section("landmarks", m.landmarks, kLandmarkFields);
  section("noise", m.noise, kNoiseFields);
  f("log_chi2", m.log_chi2);
  section("timing", m.timing, kTimingFields);
  section("run", m.run, kRunFields);
  section("calibration", m.calibration, kCalibrationFields);
  section("ground_truth", m.ground_truth, kGroundTruthFields);
};

// NaN and infinity are "unavailable" too: JSON has no spelling for them.
template <typename T>
json Put(const std::optional<T>& v) {
  if (!v) return nullptr;
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(*v)) return nullptr;
  }
  return *v;
}
template <typename T>
json Put(const T& v) {
  return v;
}
json Put(const std::vector<RunMetrics::PerObject>& objects);

template <typename Fields, typename S>
json WriteFields(const Fields& fields, const S& s) {
  json j = json::object();
  fields(s, [&](const char* key, const auto& v) { j[key] = Put(v); });
  return j;
}

json Put(const std::vector<RunMetrics::PerObject>& objects) {
  json a = json::array();
  for (const auto& o : objects) a.push_back(WriteFields(kPerObjectFields, o));
  return a;
}

// Absent and null leave a field at its default (nullopt for the optional ones).
template <typename T>
void Get(const json& object, const char* key, std::optional<T>& out) {
  out.reset();
  const auto it = object.find(key);
  if (it != object.end() && !it->is_null()) out = it->get<T>();
}
template <typename T>
void Get(const json& object, const char* key, T& out) {
  const auto it = object.find(key);
  if (it != object.end() && !it->is_null()) out = it->get<T>();
}
void Get(const json& object, const char* key, std::vector<RunMetrics::PerObject>& out);

template <typename Fields, typename S>
void ReadFields(const Fields& fields, const json& j, S& s) {
  fields(s, [&](const char* key, auto& v) { Get(j, key, v); });
}

void Get(const json& object, const char* key, std::vector<RunMetrics::PerObject>& out) {
  out.clear();
  const auto it = object.find(key);
  if (it == object.end() || !it->is_array()) return;
  for (const json& e : *it) {
    RunMetrics::PerObject p;
    ReadFields(kPerObjectFields, e, p);
    out.push_back(p);
  }
}

const json& Child(const json& object, const char* key) {
  static const json kEmpty = json::object();
  const auto it = object.find(key);
  return it == object.end() || it->is_null() ? kEmpty : *it;
}

}  // namespace

nlohmann::json ToJson(const RunMetrics& m) {
  json j = json::object();
  kRunMetricsFields(
      m, [&](const char* key, const auto& v) { j[key] = Put(v); },
      [&](const char* key, const auto& s, const auto& fields) { j[key] = WriteFields(fields, s); });
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
    if (!j.is_object()) throw InputError(source, "expected a JSON object");
    kRunMetricsFields(
        m, [&](const char* key, auto& v) { Get(j, key, v); },
        [&](const char* key, auto& s, const auto& fields) { ReadFields(fields, Child(j, key), s); });
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
