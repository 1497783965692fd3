#pragma once
// What `cslam bench` writes: bench.json (every sequence × method with all of its metrics,
// per-method means per preset, and the sweeps) and bench.md (the paper's Table 1 layout with
// means over each preset's sequences, then one row per sequence × method).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "system/run/bench_suite.h"

namespace cslam {

/// One column of Table 1: how to read it from a run's metrics.
struct BenchColumn {
  std::string key;     ///< JSON key of the means, e.g. "camera_ate_m"
  std::string header;  ///< Markdown header, e.g. "ATE cam. (m)"
  int precision = 3;   ///< decimals in the Markdown table
  std::optional<double> (*value)(const RunMetrics&) = nullptr;
};

/// log χ², RMSE, ATE camera/objects, R.RPE camera/objects, T.RPE camera/objects, Acc %,
/// β_VI, time — the paper's Table 1 columns, in its order.
const std::vector<BenchColumn>& BenchColumns();

/// Means of every column over the successful entries of one group; a column is unset when
/// no successful entry has it. `runs` counts the entries, `failed` those that threw.
struct BenchMeans {
  std::string preset;
  std::string method;  ///< BenchMethod::key
  std::string label;
  int runs = 0, failed = 0;
  std::vector<std::optional<double>> values;  ///< one per BenchColumns() entry
};
BenchMeans MeanOverEntries(const std::vector<const BenchEntry*>& entries);

/// One parameter sweep: the entries run at each value of x (noise in px, chunk length).
struct BenchSweep {
  std::string name;     ///< "noise" | "chunk"
  std::string x_label;  ///< e.g. "pixel noise (px)"
  std::vector<double> x;
  std::vector<std::vector<BenchEntry>> entries;  ///< [x index] one per sweep sequence
};

/// Everything one `cslam bench` produced.
struct BenchReport {
  BenchOptions options;
  std::vector<BenchMethod> methods;
  std::vector<BenchEntry> entries;  ///< sequence-major, methods in the paper's order
  std::vector<BenchSweep> sweeps;
  double total_s = 0.0;
  bool interrupted = false;

  /// Means per (preset, method), presets indoor then outdoor, methods in order.
  std::vector<BenchMeans> Means() const;
};

nlohmann::json BenchToJson(const BenchReport& report);
std::string BenchMarkdown(const BenchReport& report);

/// Writes DIR/bench.json and DIR/bench.md, each atomically. Throws OutputError.
void WriteBenchReport(const BenchReport& report, const std::string& dir);

}  // namespace cslam
