#include "system/run/suite_table.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/io/image_io.h"
#include "system/draw/bar_chart.h"
#include "system/draw/line_chart.h"
#include "system/run/external_trajectory.h"
#include "system/run/run_executor.h"

namespace cslam {

// bench.json's tables; a row's log tail, column values and metrics and the means' column
// values are written beside them.

template <>
struct JsonFields<SuiteRow> {
  using S = SuiteRow;
  static constexpr auto kFields = std::tuple{
      JsonField{"id", &S::id},
      JsonField{"entry", &S::entry},
      JsonField{"drive", &S::drive},
      JsonField{"system", &S::system},
      JsonField{"external", &S::external},
      JsonField{"status", &S::status},
      JsonField{"exit_code", &S::exit_code},
      JsonField{"error", &S::error},
  };
};

template <>
struct JsonFields<SuiteMeans> {
  using S = SuiteMeans;
  static constexpr auto kFields = std::tuple{
      JsonField{"system", &S::system},
      JsonField{"rows", &S::rows},
      JsonField{"ok", &S::ok},
      JsonField{"failed", &S::failed},
  };
};

namespace fs = std::filesystem;

namespace {

std::optional<double> Int(std::optional<int> v) {
  return v ? std::optional<double>(*v) : std::nullopt;
}

std::string Num(const std::optional<double>& v, int precision) {
  if (!v || !std::isfinite(*v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", precision, *v);
  return buf;
}

// The first line of the log that says what went wrong ("error:"), else its last line.
std::string ErrorLine(const std::string& tail) {
  std::istringstream s(tail);
  std::string line, last, error;
  while (std::getline(s, line)) {
    if (line.empty()) continue;
    last = line;
    if (error.empty() && (line.find("error:") != std::string::npos || line.find("[error]") != std::string::npos))
      error = line;
  }
  return error.empty() ? last : error;
}

std::string MarkdownCell(std::string s) {
  for (char& c : s)
    if (c == '|' || c == '\n') c = ' ';
  return s;
}

}  // namespace

std::string SuiteRunsFolder(const std::string& suite_out) {
  return (fs::path(suite_out) / "runs").string();
}

SuiteRow CollectRunRow(const SuiteRun& run, const std::string& runs_dir) {
  SuiteRow row;
  row.id = run.id;
  row.entry = run.entry;
  row.drive = run.drive;
  row.system = run.system;
  const std::string dir = (fs::path(runs_dir) / run.id).string();
  const std::optional<CompletionMarker> marker = ReadCompletionMarker(dir);
  if (!marker) {
    row.status = "incomplete";
    return row;
  }
  row.exit_code = marker->exit_code;
  const std::string metrics_file = (fs::path(dir) / "metrics.json").string();
  if (fs::exists(metrics_file)) {
    try {
      std::ifstream in(metrics_file);
      row.metrics = RunMetricsFromJson(nlohmann::json::parse(in), metrics_file);
    } catch (const std::exception& e) {
      row.error = metrics_file + ": unreadable: " + e.what();
    }
  }
  if (*row.exit_code == 0 && row.metrics) {
    row.status = "ok";
    return row;
  }
  row.status = "failed";
  row.log_tail = FileTail(ConsoleLogPath(dir), 12);
  if (row.error.empty()) {
    row.error = "exit code " + std::to_string(*row.exit_code);
    if (!marker->reason.empty()) row.error += ", " + marker->reason;
    else if (*row.exit_code == 0) row.error += " but no metrics.json";
    const std::string line = ErrorLine(row.log_tail);
    if (!line.empty()) row.error += ": " + line;
  }
  return row;
}

SuiteRow ScoreExternalRow(const SuiteExternal& x) {
  SuiteRow row;
  row.id = x.id;
  row.entry = x.entry;
  row.drive = x.drive;
  row.system = x.system;
  row.external = true;
  ExternalTrajectoryOptions o;
  o.input = x.input;
  o.max_frames = x.max_frames;
  o.trajectory = x.trajectory;
  o.format = x.format;
  o.frames = x.frames;
  try {
    RunMetrics m = ScoreExternalTrajectory(o, x.system);
    m.sequence = x.drive;
    row.metrics = m;
    row.status = "ok";
  } catch (const Error& e) {
    row.status = "failed";
    row.error = e.what();
  }
  return row;
}

const std::vector<SuiteColumn>& SuiteColumns() {
  static const std::vector<SuiteColumn> kColumns = {
      {"camera_ate_m", "ATE SE(3) (m)", 3, [](const RunMetrics& m) { return m.camera.ate_m; }},
      {"camera_ate_sim3_m", "ATE Sim(3) (m)", 3, [](const RunMetrics& m) { return m.camera.ate_sim3_m; }},
      {"camera_rpe_frame_t_m", "RPE t (m/frame)", 4, [](const RunMetrics& m) { return m.camera.rpe_frame_t_m; }},
      {"camera_rpe_frame_r_rad", "RPE r (rad/frame)", 5, [](const RunMetrics& m) { return m.camera.rpe_frame_r_rad; }},
      {"objects_reported", "objects reported", 1, [](const RunMetrics& m) { return Int(m.objects.reported); }},
      {"objects_matched", "objects found", 1, [](const RunMetrics& m) { return Int(m.objects.matched); }},
      {"objects_gt", "objects labelled", 1, [](const RunMetrics& m) { return Int(m.objects.gt); }},
      {"objects_ate_m", "object ATE (m)", 3, [](const RunMetrics& m) { return m.objects.ate_m; }},
      {"objects_camera_frame_m", "object error, camera frame (m)", 3,
       [](const RunMetrics& m) { return m.objects.camera_frame_rmse_m; }},
      {"objects_me_r_deg", "object ME_r (deg/frame)", 3, [](const RunMetrics& m) { return m.objects.me_r_deg; }},
      {"objects_me_t_m", "object ME_t (m/frame)", 3, [](const RunMetrics& m) { return m.objects.me_t_m; }},
      {"objects_max_turn_deg", "largest object turn (deg/frame)", 2,
       [](const RunMetrics& m) { return m.objects.max_frame_rotation_deg; }},
      {"objects_precision", "object precision", 3, [](const RunMetrics& m) { return m.objects.precision; }},
      {"objects_recall", "object recall", 3, [](const RunMetrics& m) { return m.objects.recall; }},
      {"frames_per_s", "frames/s", 2, [](const RunMetrics& m) { return m.timing.hz; }, true},
      {"peak_rss_mb", "peak RSS (MiB)", 0, [](const RunMetrics& m) { return m.timing.peak_rss_mb; }, true},
      {"time_s", "time (s)", 1, [](const RunMetrics& m) { return m.timing.total_s; }, true},
  };
  return kColumns;
}

std::vector<SuiteMeans> SuiteTable::Means() const {
  std::vector<SuiteMeans> out;
  std::map<std::string, size_t> index;
  for (const SuiteRow& r : rows)
    if (index.emplace(r.system, out.size()).second) out.push_back({r.system});
  const auto& columns = SuiteColumns();
  for (SuiteMeans& g : out) {
    std::vector<double> sum(columns.size(), 0.0);
    std::vector<int> n(columns.size(), 0);
    for (const SuiteRow& r : rows) {
      if (r.system != g.system) continue;
      ++g.rows;
      g.failed += r.status == "failed";
      if (r.status != "ok" || !r.metrics) continue;
      ++g.ok;
      for (size_t c = 0; c < columns.size(); ++c)
        if (const auto v = columns[c].value(*r.metrics); v && std::isfinite(*v)) {
          sum[c] += *v;
          ++n[c];
        }
    }
    for (size_t c = 0; c < columns.size(); ++c)
      g.values.push_back(n[c] > 0 ? std::optional<double>(sum[c] / n[c]) : std::nullopt);
  }
  return out;
}

int SuiteTable::Failed() const {
  int n = 0;
  for (const SuiteRow& r : rows) n += r.status == "failed";
  return n;
}

int SuiteTable::Incomplete() const {
  int n = 0;
  for (const SuiteRow& r : rows) n += r.status == "incomplete";
  return n;
}

SuiteTable CollectSuiteTable(const SuiteManifest& manifest, const std::string& suite_out) {
  SuiteTable t;
  t.manifest = manifest.file;
  const std::string runs = SuiteRunsFolder(suite_out);
  for (const SuiteRun& r : manifest.runs) t.rows.push_back(CollectRunRow(r, runs));
  for (const SuiteExternal& x : manifest.externals) t.rows.push_back(ScoreExternalRow(x));
  return t;
}

nlohmann::json SuiteToJson(const SuiteTable& table) {
  using nlohmann::json;
  const auto& columns = SuiteColumns();
  json rows = json::array();
  for (const SuiteRow& r : table.rows) {
    json j = FieldsToJson(r);
    if (!r.log_tail.empty()) j["log_tail"] = r.log_tail;
    json values = json::object();
    for (const SuiteColumn& c : columns)
      values[c.key] = r.metrics ? FieldValueToJson(c.value(*r.metrics)) : json(nullptr);
    j["values"] = values;
    j["metrics"] = r.metrics ? ToJson(*r.metrics) : json(nullptr);
    rows.push_back(j);
  }
  json means = json::array();
  for (const SuiteMeans& g : table.Means()) {
    json values = json::object();
    for (size_t c = 0; c < columns.size(); ++c)
      values[columns[c].key] = FieldValueToJson(g.values[c]);
    json mean = FieldsToJson(g);
    mean["values"] = values;
    means.push_back(mean);
  }
  return {{"manifest", table.manifest},
          {"executor", table.executor},
          {"total_s", table.total_s},
          {"interrupted", table.interrupted},
          {"failed", table.Failed()},
          {"incomplete", table.Incomplete()},
          {"rows", rows},
          {"means", means}};
}

std::string SuiteMarkdown(const SuiteTable& table) {
  const auto& columns = SuiteColumns();
  std::ostringstream s;
  s << "# Benchmark suite\n\nManifest: `" << table.manifest << "`, executor " << table.executor
    << ". " << table.rows.size() << " rows, " << table.Failed() << " failed, " << table.Incomplete()
    << " incomplete" << (table.interrupted ? " (interrupted)" : "") << ".\n\n";
  auto header = [&](const std::string& first) {
    s << "| " << first;
    for (const SuiteColumn& c : columns) s << " | " << c.header;
    s << " |\n|---";
    for (char ch : first)
      if (ch == '|') s << "|---";
    for (size_t c = 0; c < columns.size(); ++c) s << "|---:";
    s << "|\n";
  };
  s << "## Means per system\n\n";
  header("system | runs ok | failed");
  for (const SuiteMeans& g : table.Means()) {
    s << "| " << MarkdownCell(g.system) << " | " << g.ok << "/" << g.rows << " | " << g.failed;
    for (size_t c = 0; c < columns.size(); ++c) s << " | " << Num(g.values[c], columns[c].precision);
    s << " |\n";
  }
  s << "\n## Runs\n\n";
  header("run | drive | system | status");
  for (const SuiteRow& r : table.rows) {
    s << "| " << MarkdownCell(r.id) << " | " << MarkdownCell(r.drive) << " | " << MarkdownCell(r.system)
      << " | " << r.status << (r.exit_code && *r.exit_code != 0 ? " (" + std::to_string(*r.exit_code) + ")" : "");
    for (const SuiteColumn& c : columns)
      s << " | " << (r.metrics ? Num(c.value(*r.metrics), c.precision) : "–");
    s << " |\n";
  }
  bool any_failed = false;
  for (const SuiteRow& r : table.rows) {
    if (r.status != "failed") continue;
    if (!any_failed) s << "\n## Failed runs\n";
    any_failed = true;
    s << "\n### " << r.id << "\n\n" << MarkdownCell(r.error) << "\n";
    if (!r.log_tail.empty()) s << "\n```\n" << r.log_tail << "```\n";
  }
  return s.str();
}

namespace {

// A bar's label has room for ~16 characters: KITTI raw folders lose their date and "_sync"
// (2011_09_26_drive_0005_sync -> drive_0005), synthetic inputs their "synthetic_".
std::string ShortDriveLabel(std::string drive) {
  if (drive.size() > 11 && drive.compare(4, 1, "_") == 0 && drive.compare(7, 1, "_") == 0 &&
      drive.compare(10, 1, "_") == 0 && std::isdigit(static_cast<unsigned char>(drive[0])))
    drive = drive.substr(11);
  if (drive.size() > 5 && drive.compare(drive.size() - 5, 5, "_sync") == 0) drive.resize(drive.size() - 5);
  if (drive.rfind("synthetic_", 0) == 0) drive = drive.substr(10);
  return drive;
}

}  // namespace

void WriteSuiteTable(const SuiteTable& table, const std::string& dir) {
  WriteFileAtomically((fs::path(dir) / "bench.json").string(),
                      [&](std::ostream& o) { o << SuiteToJson(table).dump(2) << "\n"; });
  WriteFileAtomically((fs::path(dir) / "bench.md").string(),
                      [&](std::ostream& o) { o << SuiteMarkdown(table); });
  // bench.png: per-drive camera ATE (SE(3)), one bar per system.
  BarChart chart;
  chart.title = "camera ATE SE(3) per drive";
  chart.y_label = "ATE (m)";
  std::map<std::string, size_t> drive_index, system_index;
  for (const SuiteRow& r : table.rows) {
    if (drive_index.emplace(r.drive, chart.categories.size()).second)
      chart.categories.push_back(ShortDriveLabel(r.drive));
    if (system_index.emplace(r.system, chart.series.size()).second) {
      BarSeries s;
      s.label = r.system;
      s.color_bgr = SeriesColor(static_cast<int>(chart.series.size()));
      chart.series.push_back(s);
    }
  }
  for (BarSeries& s : chart.series) s.values.assign(chart.categories.size(), std::nullopt);
  for (const SuiteRow& r : table.rows)
    if (r.status == "ok" && r.metrics && r.metrics->camera.ate_m)
      chart.series[system_index[r.system]].values[drive_index[r.drive]] = *r.metrics->camera.ate_m;
  const int width = std::max(800, 160 * static_cast<int>(chart.categories.size()));
  WritePng(RenderBarChart(chart, width, 600), (fs::path(dir) / "bench.png").string());
}

}  // namespace cslam
