#include "system/run/bench_report.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>

#include "core/atomic_file.h"
#include "system/run/version.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {

// bench.json's tables; the keys that are not members (an entry's method key and label, error
// and metrics, the means' columns) are written beside them.

template <>
struct JsonFields<BenchMethod> {
  using S = BenchMethod;
  static constexpr auto kFields = std::tuple{
      JsonField{"key", &S::key},
      JsonField{"label", &S::label},
      JsonField{"method", &S::method},
      JsonField{"ablation", &S::ablation},
  };
};

template <>
struct JsonFields<BenchEntry> {
  using S = BenchEntry;
  static constexpr auto kFields = std::tuple{
      JsonField{"sequence", &S::sequence},
      JsonField{"preset", &S::preset},
      JsonField{"seed", &S::seed},
      JsonField{"noise_px", &S::noise_px},
      JsonField{"chunk_length", &S::chunk_length},
      JsonField{"ok", &S::ok},
  };
};

template <>
struct JsonFields<BenchMeans> {
  using S = BenchMeans;
  static constexpr auto kFields = std::tuple{
      JsonField{"preset", &S::preset}, JsonField{"method", &S::method},
      JsonField{"label", &S::label},   JsonField{"runs", &S::runs},
      JsonField{"failed", &S::failed},
  };
};

namespace {

using nlohmann::json;

constexpr double kDeg = 180.0 / std::numbers::pi;

std::optional<double> Scaled(const std::optional<double>& v, double s) {
  if (!v || !std::isfinite(*v)) return std::nullopt;
  return *v * s;
}

std::string Cell(const std::optional<double>& v, int precision) {
  if (!v) return "—";
  char buf[64];
  // A diverged estimate can be 1e50 m: fixed notation would fill the row with digits.
  if (std::abs(*v) >= 1e5)
    std::snprintf(buf, sizeof(buf), "%.2e", *v);
  else
    std::snprintf(buf, sizeof(buf), "%.*f", precision, *v);
  return buf;
}

// Markdown table cells must not contain '|' or line breaks.
std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += "\\|";
    else if (c == '\n' || c == '\r') out += ' ';
    else out += c;
  }
  return out;
}

json EntryJson(const BenchEntry& e) {
  json j = FieldsToJson(e);
  j["method"] = e.method.key;
  j["label"] = e.method.label;
  j["error"] = e.ok ? json(nullptr) : json(e.error);
  if (e.ok) {
    json m = ToJson(e.metrics);
    m.erase("conventions");  // written once at the top of bench.json
    j["metrics"] = m;
  } else {
    j["metrics"] = nullptr;
  }
  return j;
}

json MeansJson(const BenchMeans& m) {
  json j = FieldsToJson(m);
  for (size_t c = 0; c < BenchColumns().size(); ++c)
    j[BenchColumns()[c].key] = FieldValueToJson(m.values[c]);
  return j;
}

std::string TableHeader(const std::string& first) {
  std::string h = first, rule = "|---|---|";
  for (const BenchColumn& c : BenchColumns()) {
    h += " | " + c.header;
    rule += "---|";
  }
  return h + " |\n" + rule + "\n";
}

}  // namespace

const std::vector<BenchColumn>& BenchColumns() {
  static const std::vector<BenchColumn> kColumns = {
      {"log_chi2", "log χ²", 2, [](const RunMetrics& m) { return Scaled(m.log_chi2, 1); }},
      {"landmark_rmse_m", "RMSE (m)", 3,
       [](const RunMetrics& m) { return Scaled(m.landmarks.rmse_m, 1); }},
      {"camera_ate_m", "ATE cam. (m)", 3,
       [](const RunMetrics& m) { return Scaled(m.camera.ate_m, 1); }},
      {"objects_ate_m", "ATE obj. (m)", 3,
       [](const RunMetrics& m) { return Scaled(m.objects.ate_m, 1); }},
      {"camera_rpe_r_deg", "R.RPE cam. (°)", 3,
       [](const RunMetrics& m) { return Scaled(m.camera.rpe_frame_r_rad, kDeg); }},
      {"objects_rpe_r_deg", "R.RPE obj. (°)", 3,
       [](const RunMetrics& m) { return Scaled(m.objects.rpe_frame_r_rad, kDeg); }},
      {"camera_rpe_t_m", "T.RPE cam. (m)", 4,
       [](const RunMetrics& m) { return Scaled(m.camera.rpe_frame_t_m, 1); }},
      {"objects_rpe_t_m", "T.RPE obj. (m)", 4,
       [](const RunMetrics& m) { return Scaled(m.objects.rpe_frame_t_m, 1); }},
      {"accuracy_pct", "Acc %", 1,
       [](const RunMetrics& m) { return Scaled(m.clustering.accuracy, 100); }},
      {"vi", "β_VI", 3, [](const RunMetrics& m) { return Scaled(m.clustering.vi, 1); }},
      {"time_s", "time (s)", 1, [](const RunMetrics& m) { return Scaled(m.timing.total_s, 1); }},
  };
  return kColumns;
}

BenchMeans MeanOverEntries(const std::vector<const BenchEntry*>& entries) {
  BenchMeans out;
  const size_t nc = BenchColumns().size();
  std::vector<double> sum(nc, 0.0);
  std::vector<int> count(nc, 0);
  for (const BenchEntry* e : entries) {
    if (out.runs == 0) {
      out.preset = e->preset;
      out.method = e->method.key;
      out.label = e->method.label;
    }
    ++out.runs;
    if (!e->ok) {
      ++out.failed;
      continue;
    }
    for (size_t c = 0; c < nc; ++c)
      if (const auto v = BenchColumns()[c].value(e->metrics)) {
        sum[c] += *v;
        ++count[c];
      }
  }
  out.values.resize(nc);
  for (size_t c = 0; c < nc; ++c)
    if (count[c] > 0) out.values[c] = sum[c] / count[c];
  return out;
}

std::vector<BenchMeans> BenchReport::Means() const {
  std::vector<BenchMeans> out;
  for (const std::string preset : {"indoor", "outdoor"})
    for (const BenchMethod& m : methods) {
      std::vector<const BenchEntry*> group;
      for (const BenchEntry& e : entries)
        if (e.preset == preset && e.method.key == m.key) group.push_back(&e);
      if (group.empty()) continue;
      out.push_back(MeanOverEntries(group));
    }
  return out;
}

json BenchToJson(const BenchReport& r) {
  json j;
  j["version"] = VersionString();
  j["suite"] = r.options.suite;
  j["frames"] = r.options.frames;
  j["seeds_indoor"] = r.options.seeds_indoor;
  j["seeds_outdoor"] = r.options.seeds_outdoor;
  j["noise_px"] = FieldValueToJson(r.options.noise_px);
  j["mode"] = "batch";
  j["interrupted"] = r.interrupted;
  j["total_s"] = r.total_s;
  j["methods"] = FieldValueToJson(r.methods);
  json columns = json::array();
  for (const BenchColumn& c : BenchColumns()) columns.push_back({{"key", c.key}, {"header", c.header}});
  j["columns"] = columns;
  j["conventions"] = ToJson(RunMetrics{})["conventions"];
  json entries = json::array();
  for (const BenchEntry& e : r.entries) entries.push_back(EntryJson(e));
  j["entries"] = entries;
  json means = json::array();
  for (const BenchMeans& m : r.Means()) means.push_back(MeansJson(m));
  j["means"] = means;
  json sweeps = json::object();
  for (const BenchSweep& s : r.sweeps) {
    json points = json::array();
    for (size_t i = 0; i < s.x.size(); ++i) {
      std::vector<const BenchEntry*> group;
      json runs = json::array();
      for (const BenchEntry& e : s.entries[i]) {
        group.push_back(&e);
        runs.push_back(EntryJson(e));
      }
      json p = {{"x", s.x[i]}, {"mean", group.empty() ? json(nullptr) : MeansJson(MeanOverEntries(group))},
                {"entries", runs}};
      points.push_back(p);
    }
    sweeps[s.name] = {{"x_label", s.x_label}, {"points", points}};
  }
  j["sweeps"] = sweeps;
  return j;
}

std::string BenchMarkdown(const BenchReport& r) {
  std::ostringstream s;
  s << "# cslam bench — suite " << r.options.suite << "\n\n";
  s << "Batch mode on replayed tracklets; " << (r.options.frames > 0 ? "first " + std::to_string(r.options.frames) + " frames" : "whole sequences")
    << "; indoor seeds 1.." << r.options.seeds_indoor << ", outdoor seeds 1.." << r.options.seeds_outdoor
    << "; pixel noise " << Cell(r.options.noise_px.value_or(SyntheticOptions{}.noise_px), 2) << " px. "
    << "Version " << VersionString() << ", " << Cell(r.total_s, 0) << " s in all"
    << (r.interrupted ? " (interrupted: some runs are missing)" : "") << ".\n\n";
  s << "## Means over each preset's sequences (Table 1 layout)\n\n";
  s << "RPE per frame (RMSE); objects: mean over matched objects; Acc and β_VI (natural log) over "
       "landmarks with ≥ 4 observations. A mean leaves out failed runs (counted in `runs`).\n\n";
  s << "| preset | method | runs";
  std::string rule = "|---|---|---|";
  for (const BenchColumn& c : BenchColumns()) {
    s << " | " << c.header;
    rule += "---|";
  }
  s << " |\n" << rule << "\n";
  for (const BenchMeans& m : r.Means()) {
    s << "| " << m.preset << " | " << m.label << " | " << (m.runs - m.failed) << "/" << m.runs;
    for (size_t c = 0; c < BenchColumns().size(); ++c)
      s << " | " << Cell(m.values[c], BenchColumns()[c].precision);
    s << " |\n";
  }
  s << "\n## Per sequence\n\n" << TableHeader("| sequence | method");
  for (const BenchEntry& e : r.entries) {
    s << "| " << e.sequence << " | " << e.method.label;
    if (!e.ok) {
      s << " | failed: " << Escape(e.error);
      for (size_t c = 1; c < BenchColumns().size(); ++c) s << " | ";
      s << " |\n";
      continue;
    }
    for (const BenchColumn& c : BenchColumns()) s << " | " << Cell(c.value(e.metrics), c.precision);
    s << " |\n";
  }
  for (const BenchSweep& sw : r.sweeps) {
    s << "\n## Sweep: " << sw.name << " (" << (sw.entries.empty() || sw.entries[0].empty() ? std::string("—") : sw.entries[0][0].method.label)
      << ", means over " << (sw.entries.empty() ? 0 : sw.entries[0].size()) << " sequences)\n\n"
      << TableHeader("| " + sw.x_label + " | runs");
    for (size_t i = 0; i < sw.x.size(); ++i) {
      std::vector<const BenchEntry*> group;
      for (const BenchEntry& e : sw.entries[i]) group.push_back(&e);
      const BenchMeans m = MeanOverEntries(group);
      s << "| " << Cell(sw.x[i], sw.name == "noise" ? 1 : 0) << " | " << (m.runs - m.failed) << "/" << m.runs;
      for (size_t c = 0; c < BenchColumns().size(); ++c)
        s << " | " << Cell(m.values[c], BenchColumns()[c].precision);
      s << " |\n";
    }
    s << "\n![" << sw.name << "](sweep_" << sw.name << ".png)\n";
  }
  return s.str();
}

void WriteBenchReport(const BenchReport& report, const std::string& dir) {
  const json j = BenchToJson(report);
  WriteFileAtomically(dir + "/bench.json", [&](std::ostream& o) { o << j.dump(2) << "\n"; });
  const std::string md = BenchMarkdown(report);
  WriteFileAtomically(dir + "/bench.md", [&](std::ostream& o) { o << md; });
}

}  // namespace cslam
