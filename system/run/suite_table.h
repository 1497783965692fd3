#pragma once
// What `cslam bench --suite FILE.yaml` and `cslam bench collect DIR` write: one row per run
// and per external trajectory, read back from the runs' folders (metrics.json, exit_code,
// console.log), means per system, and the files DIR/bench.json, DIR/bench.md and
// DIR/bench.png (per-drive camera ATE, one bar per system).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "system/eval/metrics_json.h"
#include "system/run/suite_manifest.h"

namespace cslam {

/// One row of the table.
struct SuiteRow {
  std::string id, entry, drive, system;
  bool external = false;
  /// "ok", "failed" (ended with a non-zero exit code or unreadable outputs) or "incomplete"
  /// (no completion marker: not run yet, still running or interrupted).
  std::string status = "incomplete";
  std::optional<int> exit_code;
  std::string error;     ///< why it failed: the marker's reason, the error line of the log
  std::string log_tail;  ///< last lines of console.log (failed rows)
  std::optional<RunMetrics> metrics;  ///< read from metrics.json (also for a failed run that wrote it)
};

/// The row of a run from its folder `runs_dir`/<id>.
SuiteRow CollectRunRow(const SuiteRun& run, const std::string& runs_dir);
/// The row of an external trajectory: scored now; a bad file makes a failed row naming it.
SuiteRow ScoreExternalRow(const SuiteExternal& external);

/// One column of the table and how to read it from the metrics.
struct SuiteColumn {
  std::string key;     ///< JSON key of the means
  std::string header;  ///< Markdown header
  int precision = 3;
  std::optional<double> (*value)(const RunMetrics&) = nullptr;
  bool timing = false;  ///< depends on the machine (time, frames/s, memory)
};
/// ATE SE(3), ATE Sim(3), RPE/frame t and r, reported objects, matched/labelled objects,
/// object ATE, precision, recall, frames/s, peak RSS, total time.
const std::vector<SuiteColumn>& SuiteColumns();

/// Means of every column over the ok rows of one system.
struct SuiteMeans {
  std::string system;
  int rows = 0, ok = 0, failed = 0;
  std::vector<std::optional<double>> values;  ///< one per SuiteColumns() entry
};

/// The whole table.
struct SuiteTable {
  std::string manifest;
  std::string executor;
  std::vector<SuiteRow> rows;  ///< runs in manifest order, then externals
  double total_s = 0.0;
  bool interrupted = false;

  std::vector<SuiteMeans> Means() const;  ///< per system, in order of first appearance
  int Failed() const;
  int Incomplete() const;
};

/// Builds the table of `manifest` from `suite_out`/runs and scores its externals.
SuiteTable CollectSuiteTable(const SuiteManifest& manifest, const std::string& suite_out);

nlohmann::json SuiteToJson(const SuiteTable& table);
std::string SuiteMarkdown(const SuiteTable& table);

/// Writes DIR/bench.json, DIR/bench.md and DIR/bench.png, each atomically. Throws OutputError.
void WriteSuiteTable(const SuiteTable& table, const std::string& dir);

/// The runs' folder of a suite output folder: DIR/runs.
std::string SuiteRunsFolder(const std::string& suite_out);

}  // namespace cslam
