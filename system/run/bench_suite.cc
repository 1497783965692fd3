#include "system/run/bench_suite.h"

#include <algorithm>
#include <exception>

#include "core/errors.h"
#include "core/logging.h"
#include "system/pipeline/pipeline.h"
#include "system/run/run_metrics.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {

const std::vector<BenchMethod>& BenchMethods() {
  static const std::vector<BenchMethod> kMethods = {
      {"full-ba", "Full BA", "full-ba", "none"},
      {"pdcs", "P. DCS", "pdcs", "none"},
      {"clusterslam-no-u", "Ours w/o U", "clusterslam", "no-u"},
      {"clusterslam-no-i", "Ours w/o I", "clusterslam", "no-i"},
      {"clusterslam", "Ours", "clusterslam", "none"},
      {"true-labels", "True labels", "true-labels", "none", /*in_paper=*/false},
  };
  return kMethods;
}

const BenchMethod& FindBenchMethod(const std::string& key) {
  std::string known;
  for (const BenchMethod& m : BenchMethods()) {
    if (m.key == key) return m;
    known += (known.empty() ? "" : ", ") + m.key;
  }
  throw ConfigError("--methods: unknown method '" + key + "' (known: " + known + ")");
}

void BenchOptions::Check() const {
  if (suite != "synthetic")
    throw ConfigError("--suite: unknown suite '" + suite + "' (known: synthetic, or a suite manifest FILE.yaml)");
  CheckOption(frames == 0 || frames >= 2, "--frames", "must be 0 (whole sequence) or >= 2", frames);
  CheckOption(seeds_indoor >= 0, "--seeds-indoor", "must be >= 0", seeds_indoor);
  CheckOption(seeds_outdoor >= 0, "--seeds-outdoor", "must be >= 0", seeds_outdoor);
  if (seeds_indoor + seeds_outdoor == 0)
    throw ConfigError("--seeds-indoor / --seeds-outdoor: the suite has no sequence");
  if (noise_px) CheckOption(*noise_px >= 0, "--noise", "must be >= 0 px", *noise_px);
  for (const std::string& k : methods) FindBenchMethod(k);
}

std::vector<BenchMethod> BenchOptions::SelectedMethods() const {
  std::vector<BenchMethod> out;
  for (const BenchMethod& m : BenchMethods())
    if (methods.empty() ? m.in_paper
                        : std::find(methods.begin(), methods.end(), m.key) != methods.end())
      out.push_back(m);
  return out;
}

std::vector<BenchSequence> SuiteSequences(const BenchOptions& options) {
  const double noise = options.noise_px.value_or(SyntheticOptions{}.noise_px);
  std::vector<BenchSequence> out;
  for (int s = 1; s <= options.seeds_indoor; ++s) out.push_back({"indoor", s, noise});
  for (int s = 1; s <= options.seeds_outdoor; ++s) out.push_back({"outdoor", s, noise});
  return out;
}

RunInput GenerateBenchInput(const BenchSequence& sequence, int frames) {
  SyntheticOptions o;
  o.preset = sequence.preset;
  o.seed = sequence.seed;
  o.noise_px = sequence.noise_px;
  // The whole sequence is generated and then cut, so "the first N frames" of a seed are the
  // same frames whatever N is (the generator's trajectories depend on the length).
  return SyntheticRunInput(GenerateSynthetic(o), frames);
}

PipelineOptions BenchPipelineOptions(const std::string& preset, const BenchMethod& method,
                                     int chunk_length) {
  PipelineOptions o;
  o.ApplyPreset(ParseEnum(kPresetNames, preset, "preset"));
  o.method = ParseEnum(kMethodNames, method.method, "method");
  o.ApplyAblation(ParseEnum(kAblationNames, method.ablation, "ablation"));
  o.mode = RunMode::kBatch;
  o.output.trajectory_plot = false;
  if (chunk_length > 0) {
    o.backend.consensus.chunk_length = chunk_length;
    o.backend.consensus.chunk_overlap =
        std::min(o.backend.consensus.chunk_overlap, chunk_length / 2);
  }
  o.Check();
  return o;
}

BenchEntry RunBenchEntry(const RunInput& input, const BenchSequence& sequence,
                         const BenchMethod& method, const PipelineOptions& options,
                         const std::atomic<bool>* stop) {
  auto log = GetLogger("system");
  BenchEntry e;
  e.sequence = input.name;
  e.preset = sequence.preset;
  e.seed = sequence.seed;
  e.noise_px = sequence.noise_px;
  e.chunk_length = options.backend.consensus.chunk_length;
  e.method = method;
  log->info("bench: {} ({} frames) × {}", input.name, input.num_frames(), method.label);
  try {
    PipelineResult result = RunPipeline(input, options, stop);
    if (result.error) std::rethrow_exception(result.error);
    if (result.interrupted) throw std::runtime_error("interrupted");
    if (!result.windows.empty() && result.windows.front().failed)
      throw std::runtime_error("the backend gave no usable estimate (non-finite or empty)");
    e.metrics = ComputeRunMetrics(input, result, BuildRunTrajectories(result.map, input.timestamps),
                                  options);
    e.ok = true;
  } catch (const std::exception& ex) {
    e.error = ex.what();
    log->error("bench: {} × {} failed: {}", input.name, method.label, e.error);
  }
  return e;
}

}  // namespace cslam
