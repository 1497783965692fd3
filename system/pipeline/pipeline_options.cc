#include "system/pipeline/pipeline_options.h"

#include <algorithm>

#include "core/errors.h"
#include "system/pipeline/builtin_configs.h"

namespace cslam {

void OnlineOptions::Check() const {
  CheckOption(window_frames >= 5, "online.window_frames", "must be at least 5 frames", window_frames);
  CheckOption(window_every >= 1 && window_every <= window_frames - 2, "online.window_every",
              "must be in [1, window_frames - 2] so consecutive windows share frames", window_every);
  CheckOption(frame_queue >= 1, "online.frame_queue", "must be >= 1", frame_queue);
  CheckOption(window_queue >= 1, "online.window_queue", "must be >= 1", window_queue);
  CheckOption(background_nice >= 0 && background_nice <= 19, "online.background_nice",
              "must be in [0, 19] (a nice increment; threads can only lower their priority)",
              background_nice);
  CheckOption(min_shared_landmarks >= 1, "online.min_shared_landmarks", "must be >= 1",
              min_shared_landmarks);
}

void OnlineOptions::Load(OptionsReader& r) {
  r.Read("window_frames", &window_frames);
  r.Read("window_every", &window_every);
  r.Read("frame_queue", &frame_queue);
  r.Read("window_queue", &window_queue);
  r.Read("realtime", &realtime);
  r.Read("sequential", &sequential);
  r.Read("background_nice", &background_nice);
  r.Read("reserve_core", &reserve_core);
  r.Read("min_shared_landmarks", &min_shared_landmarks);
  r.Read("forget_observations", &forget_observations);
  r.Finish();
}

void BatchOptions::Check() const {
  CheckOption(max_iterations >= 1, "batch.max_iterations", "must be >= 1", max_iterations);
  CheckOption(ba_iterations >= 1, "batch.ba_iterations", "must be >= 1", ba_iterations);
}

void BatchOptions::Load(OptionsReader& r) {
  r.Read("warm_start", &warm_start);
  r.Read("max_iterations", &max_iterations);
  r.Read("ba_iterations", &ba_iterations);
  r.Read("native_sparse_solver", &native_sparse_solver);
  r.Finish();
}

void OutputOptions::Check() const {
  CheckOption(snapshots_every >= 0, "output.snapshots_every", "must be >= 0 (0 = off)", snapshots_every);
  CheckOption(overlays_every >= 0, "output.overlays_every", "must be >= 0 (0 = off)", overlays_every);
}

void OutputOptions::Load(OptionsReader& r) {
  r.Read("snapshots_every", &snapshots_every);
  r.Read("overlays_every", &overlays_every);
  r.Read("dense_snapshots", &dense_snapshots);
  r.Read("trajectory_plot", &trajectory_plot);
  r.Finish();
}

namespace {
void CheckMember(const std::string& key, const std::string& value,
                 std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return;
    list += std::string(list.empty() ? "" : ", ") + a;
  }
  throw ConfigError(key + ": must be one of " + list + ", got '" + value + "'");
}
}  // namespace

void PipelineOptions::Check() const {
  CheckMember("preset", preset, {"indoor", "outdoor"});
  CheckMember("method", method, {"clusterslam", "full-ba", "pdcs", "true-labels"});
  CheckMember("ablation", ablation, {"none", "no-u", "no-i", "p2p-icp"});
  CheckMember("mode", mode, {"online", "batch"});
  CheckOption(backend_threads >= 1, "backend_threads", "must be >= 1", backend_threads);
  input.Check();
  frontend.Check();
  backend.Check();
  online.Check();
  batch.Check();
  map.Check();
  sanity.Check();
  calibration.Check();
  output.Check();
}

void PipelineOptions::ApplyPreset(const std::string& preset_name) {
  CheckMember("preset", preset_name, {"indoor", "outdoor"});
  preset = preset_name;
  backend = preset == "indoor" ? ClusterSlamOptions::Indoor() : ClusterSlamOptions::Outdoor();
  ApplyAblation(ablation);
}

void PipelineOptions::ApplyAblation(const std::string& ablation_name) {
  CheckMember("ablation", ablation_name, {"none", "no-u", "no-i", "p2p-icp"});
  ablation = ablation_name;
  std::string yaml_name = ablation;  // the backend spells them with underscores
  std::replace(yaml_name.begin(), yaml_name.end(), '-', '_');
  backend.ablation = ParseAblation(yaml_name, "ablation");
}

void PipelineOptions::Load(OptionsReader& r) {
  std::string p = preset;
  r.Read("preset", &p);
  if (!r.dumping() && p != preset) ApplyPreset(p);
  r.Read("method", &method);
  std::string a = ablation;
  r.Read("ablation", &a);
  if (!r.dumping() && a != ablation) ApplyAblation(a);
  r.Read("mode", &mode);
  r.Read("backend_threads", &backend_threads);
  auto in = r.Section("input");
  input.Load(in);
  auto fe = r.Section("frontend");
  frontend.Load(fe);
  auto be = r.Section("backend");
  backend.Load(be);
  auto on = r.Section("online");
  online.Load(on);
  auto ba = r.Section("batch");
  batch.Load(ba);
  auto mp = r.Section("map");
  map.Load(mp);
  auto sa = r.Section("sanity");
  sanity.Load(sa);
  auto ca = r.Section("calibration");
  calibration.Load(ca);
  auto outp = r.Section("output");
  output.Load(outp);
  r.Finish();
}

std::string PipelineOptions::ToYaml() const {
  auto dump = OptionsReader::ForDump();
  PipelineOptions copy = *this;  // Load in dump mode only reads the fields out
  copy.Load(dump);
  return dump.Dump();
}

PipelineOptions LoadPipelineOptions(const std::string& preset, const std::string& config_file,
                                    const std::string& input_kind) {
  PipelineOptions o;
  o.ApplyPreset(preset);
  const std::optional<BuiltinConfig> builtin =
      config_file.empty() ? BuiltinConfigFor(input_kind) : std::nullopt;
  if (builtin) {
    YAML::Node node = YAML::Load(builtin->yaml);
    node.remove("output");  // renders stay as the defaults say
    OptionsReader r(node, "built-in " + builtin->name);
    o.Load(r);
    o.source = "built-in " + builtin->name + " (recommended for " + input_kind +
               " input; its output section not applied)";
  }
  if (!config_file.empty()) {
    o.source = config_file;
    auto r = OptionsReader::FromFile(config_file);
    o.Load(r);
    // A value out of range came from the file: name it (Check() only knows the key).
    try {
      o.Check();
    } catch (const ConfigError& e) {
      throw ConfigError(config_file + ": " + e.what());
    }
  }
  o.Check();
  return o;
}

}  // namespace cslam
