#include "system/pipeline/pipeline_options.h"

#include "core/errors.h"
#include "system/pipeline/builtin_configs.h"

namespace cslam {

void OnlineOptions::Check() const {
  CheckOption(window_frames >= 5, "window_frames", "must be at least 5 frames", window_frames);
  CheckOption(window_every >= 1 && window_every <= window_frames - 2, "window_every",
              "must be in [1, window_frames - 2] so consecutive windows share frames", window_every);
  CheckOption(frame_queue >= 1, "frame_queue", "must be >= 1", frame_queue);
  CheckOption(window_queue >= 1, "window_queue", "must be >= 1", window_queue);
  CheckOption(background_nice >= 0 && background_nice <= 19, "background_nice",
              "must be in [0, 19] (a nice increment; threads can only lower their priority)",
              background_nice);
  CheckOption(min_shared_landmarks >= 1, "min_shared_landmarks", "must be >= 1",
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
}

void BatchOptions::Check() const {
  CheckOption(max_iterations >= 1, "max_iterations", "must be >= 1", max_iterations);
  CheckOption(ba_iterations >= 1, "ba_iterations", "must be >= 1", ba_iterations);
}

void BatchOptions::Load(OptionsReader& r) {
  r.Read("warm_start", &warm_start);
  r.Read("max_iterations", &max_iterations);
  r.Read("ba_iterations", &ba_iterations);
  r.Read("native_sparse_solver", &native_sparse_solver);
}

void OutputOptions::Check() const {
  CheckOption(snapshots_every >= 0, "snapshots_every", "must be >= 0 (0 = off)", snapshots_every);
  CheckOption(overlays_every >= 0, "overlays_every", "must be >= 0 (0 = off)", overlays_every);
  CheckOption(final_pictures >= 0 && final_pictures <= 100, "final_pictures",
              "must be in [0, 100] (0 = off)", final_pictures);
}

void OutputOptions::Load(OptionsReader& r) {
  r.Read("snapshots_every", &snapshots_every);
  r.Read("overlays_every", &overlays_every);
  r.Read("dense_snapshots", &dense_snapshots);
  r.Read("trajectory_plot", &trajectory_plot);
  r.Read("final_pictures", &final_pictures);
  r.Read("view_page", &view_page);
}

void PipelineOptions::Check() const {
  CheckOption(backend_threads >= 1, "backend_threads", "must be >= 1", backend_threads);
  CheckOption(frontend_threads >= 1, "frontend_threads", "must be >= 1", frontend_threads);
  CheckSection("input", [&] { input.Check(); });
  CheckSection("frontend", [&] { frontend.Check(); });
  CheckSection("backend", [&] { backend.Check(); });
  CheckSection("online", [&] { online.Check(); });
  CheckSection("batch", [&] { batch.Check(); });
  CheckSection("map", [&] { map.Check(); });
  CheckSection("sanity", [&] { sanity.Check(); });
  CheckSection("calibration", [&] { calibration.Check(); });
  CheckSection("output", [&] { output.Check(); });
}

void PipelineOptions::ApplyPreset(Preset preset_value) {
  preset = preset_value;
  backend = preset == Preset::kIndoor ? ClusterSlamOptions::Indoor() : ClusterSlamOptions::Outdoor();
  ApplyAblation(ablation);
}

void PipelineOptions::ApplyAblation(ClusterSlamAblation ablation_value) {
  ablation = ablation_value;
  backend.ablation = ablation;
}

void PipelineOptions::Load(OptionsReader& r) {
  Preset p = preset;
  r.Read("preset", kPresetNames, &p);
  if (!r.dumping() && p != preset) ApplyPreset(p);
  r.Read("method", kMethodNames, &method);
  ClusterSlamAblation a = ablation;
  r.Read("ablation", kAblationNames, &a);
  if (!r.dumping() && a != ablation) ApplyAblation(a);
  r.Read("mode", kRunModeNames, &mode);
  r.Read("backend_threads", &backend_threads);
  r.Read("frontend_threads", &frontend_threads);
  r.ReadSection("input", &input);
  r.ReadSection("frontend", &frontend);
  r.ReadSection("backend", &backend);
  r.ReadSection("online", &online);
  r.ReadSection("batch", &batch);
  r.ReadSection("map", &map);
  r.ReadSection("sanity", &sanity);
  r.ReadSection("calibration", &calibration);
  r.ReadSection("output", &output);
}

std::string PipelineOptions::ToYaml() const {
  auto dump = OptionsReader::ForDump();
  PipelineOptions copy = *this;  // Load in dump mode only reads the fields out
  dump.LoadInto(&copy);
  return dump.Dump();
}

PipelineOptions LoadPipelineOptions(Preset preset, const std::string& config_file,
                                    std::optional<InputKind> input_kind) {
  PipelineOptions o;
  o.ApplyPreset(preset);
  // The recommended settings for the input come first and a given file changes only the keys
  // it sets: a file that tunes one value must not silently drop the rest of them.
  const std::optional<BuiltinConfig> builtin =
      input_kind ? BuiltinConfigFor(*input_kind) : std::nullopt;
  if (builtin) {
    YAML::Node node = YAML::Load(builtin->yaml);
    node.remove("output");  // renders stay as the defaults (or the given file) say
    OptionsReader r(node, "built-in " + builtin->name);
    r.LoadInto(&o);
    o.source = "built-in " + builtin->name + " (recommended for " + NameOf(kInputKindNames, *input_kind) +
               " input; its output section not applied)";
  }
  if (!config_file.empty()) {
    o.source = builtin ? config_file + " over the " + o.source : config_file;
    auto r = OptionsReader::FromFile(config_file);
    r.LoadInto(&o);
    // A value out of range came from the file: name it and the line (Check() knows the key).
    try {
      o.Check();
    } catch (const ConfigError& e) {
      const int line = e.key().empty() ? 0 : r.LineOf(e.key());
      throw ConfigError(config_file + (line > 0 ? ":" + std::to_string(line) : "") + ": " +
                        e.what());
    }
  }
  o.Check();
  return o;
}

}  // namespace cslam
