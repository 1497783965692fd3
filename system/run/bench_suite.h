#pragma once
// `cslam bench`: the paper's Table 1 protocol on generated synthetic sequences. Each backend
// method runs in batch mode on the replayed tracklets of each sequence (no images), and the
// metrics are exactly those of `cslam run` (run_metrics.h). A method that throws on a
// sequence is recorded as failed with its message; the suite goes on.
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "system/eval/metrics_json.h"
#include "system/pipeline/pipeline_options.h"
#include "system/pipeline/run_input.h"

namespace cslam {

/// One row of Table 1: a backend method, possibly with an ablation.
struct BenchMethod {
  std::string key;       ///< command-line name, e.g. "clusterslam-no-u"
  std::string label;     ///< the paper's row name, e.g. "Ours w/o U"
  std::string method;    ///< PipelineOptions::method
  std::string ablation;  ///< PipelineOptions::ablation
  bool in_paper = true;  ///< one of the paper's five rows, run when --methods is not given
};

/// Full BA, P. DCS, Ours w/o U, Ours w/o I, Ours — in the paper's row order — then the
/// reference "True labels" (ours, not the paper's: the estimation with the generator's
/// labels, the camera and objects a perfect clustering would give).
const std::vector<BenchMethod>& BenchMethods();

/// The method named `key`; throws ConfigError listing the known keys otherwise.
const BenchMethod& FindBenchMethod(const std::string& key);

/// What the suite contains and how it runs.
struct BenchOptions {
  std::string suite = "synthetic";   ///< the only suite so far
  int frames = 0;                    ///< cap every sequence to its first N frames; 0 = whole
  int seeds_indoor = 6;              ///< indoor sequences, seeds 1..K
  int seeds_outdoor = 4;             ///< outdoor sequences, seeds 1..K
  std::vector<std::string> methods;  ///< BenchMethod keys; empty = the paper's five
  std::optional<double> noise_px;    ///< generator pixel noise; unset = the generator's default

  /// Throws ConfigError naming the flag and the rule.
  void Check() const;
  /// The methods to run, in the paper's order (duplicates removed).
  std::vector<BenchMethod> SelectedMethods() const;
};

/// One generated sequence of the suite.
struct BenchSequence {
  std::string preset;  ///< indoor | outdoor
  int seed = 1;
  double noise_px = 0.0;
};

/// The sequences of the suite: indoor seeds 1..K, then outdoor seeds 1..K.
std::vector<BenchSequence> SuiteSequences(const BenchOptions& options);

/// Generates `sequence` and opens it as replayed tracklets cut to `frames` (0 = all).
RunInput GenerateBenchInput(const BenchSequence& sequence, int frames);

/// One (sequence, method) run.
struct BenchEntry {
  std::string sequence;  ///< e.g. "indoor_seed1"
  std::string preset;
  int seed = 0;
  double noise_px = 0.0;
  int chunk_length = 0;  ///< the consensus chunk length used
  BenchMethod method;
  bool ok = false;
  std::string error;     ///< why it failed (ok = false)
  RunMetrics metrics;    ///< empty when failed
};

/// Backend parameters for an entry: the preset's, `method`, batch mode; chunk_length > 0
/// overrides the consensus chunk length (the overlap is kept below it).
PipelineOptions BenchPipelineOptions(const std::string& preset, const BenchMethod& method,
                                     int chunk_length = 0);

/// Runs `options` on `input` and computes its metrics; never throws for a failing method —
/// the entry records the error instead.
BenchEntry RunBenchEntry(const RunInput& input, const BenchSequence& sequence,
                         const BenchMethod& method, const PipelineOptions& options,
                         const std::atomic<bool>* stop = nullptr);

}  // namespace cslam
