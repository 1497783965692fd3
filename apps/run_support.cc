#include "apps/run_support.h"

#include <spdlog/sinks/basic_file_sink.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/logging.h"
#include "core/options_reader.h"
#include "core/timer.h"
#include "system/run/output_folder.h"
#include "system/run/run_metrics.h"
#include "system/run/run_trajectories.h"
#include "system/run/run_writer.h"
#include "system/run/version.h"

namespace cslam::apps {

namespace fs = std::filesystem;

namespace {
// Signal handlers can only reach process-wide state; this is the one place the program has it.
std::atomic<bool> g_stop_requested{false};
std::atomic<int> g_signal{0};

extern "C" void OnSignal(int sig) {
  if (g_stop_requested.exchange(true)) std::_Exit(sig == SIGINT ? kExitSigint : kExitSigterm);
  g_signal = sig;
  const char msg[] = "\ncslam: stopping — writing what was estimated so far (again to quit now)\n";
  (void)!write(2, msg, sizeof(msg) - 1);
}
}  // namespace

void RunFlags::Register(CLI::App* sub) {
  sub->add_option("--config", config, "YAML configuration (see configs/)")->check(CLI::ExistingFile);
  sub->add_option("--preset", preset, "backend parameters: indoor or outdoor")
      ->check(CLI::IsMember(NamesOf(kPresetNames)));
  sub->add_option("--method", method,
                  "backend: clusterslam, full-ba, pdcs, or true-labels (the reference with the "
                  "generator's labels; synthetic sequences without images)")
      ->check(CLI::IsMember(NamesOf(kMethodNames)));
  sub->add_option("--ablation", ablation, "none, no-u, no-i or p2p-icp")
      ->check(CLI::IsMember(NamesOf(kAblationNames)));
  sub->add_option("--mode", mode, "online (sliding windows, default) or batch (whole sequence)")
      ->check(CLI::IsMember(NamesOf(kRunModeNames)));
  sub->add_flag("--realtime", realtime, "pace the input by its timestamps; skip windows when late");
  sub->add_flag("--sequential", sequential, "run the online stages in one thread (deterministic)");
  sub->add_option("--snapshots-every", snapshots_every,
                  "online-state snapshot every N frames, drawn during the run (0: off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--overlays-every", overlays_every,
                  "online-state keypoint overlay every N frames, drawn during the run (0: off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--pictures", pictures,
                  "final-state snapshots and overlays at N frames spread over the run, drawn "
                  "after it from its outputs (default 3; 0: none)")
      ->check(CLI::Range(0, 100));
  sub->add_option("--max-frames", max_frames, "process only the first N frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--cameras", cameras,
                  "KITTI raw: grey (image_00/01) or color (image_02/03); default: the "
                  "configuration's input.color, else grey (color when only image_02/03 exist)")
      ->check(CLI::IsMember({"grey", "color"}));
  sub->add_flag("!--no-progress", progress, "no progress bar");
  sub->add_flag("--overwrite", overwrite,
                "replace the outputs of an earlier run in --out (only the files it wrote)");
  sub->add_flag("-v,--verbose", verbose, "the whole log on the console (one line per window)");
}

InputOptions RunFlags::InputOptionsFor() const {
  // The input section of --config decides the cameras too, so it is read before the input is
  // opened (the rest of the file waits for the input's kind).
  InputOptions o = config.empty() ? InputOptions{} : LoadPipelineOptions(Preset::kOutdoor, config).input;
  if (!cameras.empty()) o.color = cameras == "color";
  if (max_frames > 0) o.max_frames = max_frames;
  return o;
}

PipelineOptions RunFlags::Resolve(const RunInput& input) const {
  Preset p = Preset::kOutdoor;
  if (!preset.empty())
    p = ParseEnum(kPresetNames, preset, "--preset");
  else if (input.synthetic && input.synthetic->name.rfind("indoor", 0) == 0)
    p = Preset::kIndoor;
  PipelineOptions o = LoadPipelineOptions(p, config, input.kind);
  if (!preset.empty()) o.ApplyPreset(p);
  if (!method.empty()) o.method = ParseEnum(kMethodNames, method, "--method");
  if (!ablation.empty()) o.ApplyAblation(ParseEnum(kAblationNames, ablation, "--ablation"));
  if (!mode.empty()) o.mode = ParseEnum(kRunModeNames, mode, "--mode");
  if (realtime) o.online.realtime = true;
  if (sequential) o.online.sequential = true;
  if (snapshots_every >= 0) o.output.snapshots_every = snapshots_every;
  if (overlays_every >= 0) o.output.overlays_every = overlays_every;
  if (pictures >= 0) o.output.final_pictures = pictures;
  o.input = InputOptionsFor();
  // A drive with only the colour pair runs on it (OpenRunInput): the configuration says so.
  if (input.kind == InputKind::kKittiRaw && input.color) o.input.color = true;
  o.Check();
  return o;
}

void PrepareRunFolder(const std::string& out, const std::string& command, const RunInput& input,
                      const RunFlags& flags) {
  OutputManifest m;
  m.version = VersionString();
  m.command = command;
  std::error_code ec;
  const fs::path abs = fs::absolute(input.path, ec);
  m.input.path = ec ? input.path : abs.lexically_normal().string();
  m.input.kind = NameOf(kInputKindNames, input.kind);
  m.input.cameras = input.color ? "color" : "grey";
  m.input.max_frames = flags.max_frames;
  PrepareOutputFolder(out, flags.overwrite, m);
}

void QuietConsole(bool verbose) {
  // The info log of a run goes to run.log; the console keeps warnings (the level asked for
  // with --log-level still holds when it is stricter, and a lower one shows everything).
  const auto def = spdlog::default_logger();
  if (!verbose && def->level() >= spdlog::level::info)
    for (const auto& console : def->sinks()) console->set_level(spdlog::level::warn);
}

void AttachLogFile(const std::string& path) {
  auto sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path, true);
  sink->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  // apply_all holds the registry lock: fetch the default logger before, not inside it.
  const auto def = spdlog::default_logger();
  def->sinks().push_back(sink);
  spdlog::apply_all([&](const std::shared_ptr<spdlog::logger>& l) {
    if (l != def) l->sinks().push_back(sink);
  });
}

void LogToRunLogOnly(const std::string& text) {
  const auto def = spdlog::default_logger();
  if (def->sinks().size() < 2) return;  // no run.log attached
  spdlog::logger file_only("app", def->sinks().back());
  file_only.set_level(def->level());
  file_only.info("{}", text);
  file_only.flush();
}

void PrintRunHeader(const RunInput& input, const PipelineOptions& options, const std::string& out) {
  const std::string line = fmt::format("{} ({}, {} frames{}) -> {}", input.path,
                                       NameOf(kInputKindNames, input.kind), input.num_frames(),
                                       input.color ? ", colour pair" : "", out);
  std::printf("input: %s\nconfiguration: %s (all values in %s/config.yaml)\n", line.c_str(),
              options.source.c_str(), out.c_str());
  std::fflush(stdout);
  GetLogger("app")->info("{}", line);
  for (const std::string& note : input.notes) GetLogger("app")->info("{}", note);
  GetLogger("app")->info("configuration: {}", options.source);
  LogToRunLogOnly("effective configuration:\n" + options.ToYaml());
}

StopFlag::StopFlag() {
  g_stop_requested = false;
  g_signal = 0;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
}
StopFlag::~StopFlag() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}
const std::atomic<bool>* StopFlag::flag() const { return &g_stop_requested; }
int StopFlag::signal() const { return g_signal.load(); }

ProgressBar::ProgressBar(std::string what, bool enabled)
    : what_(std::move(what)), enabled_(enabled && isatty(2)) {}

void ProgressBar::Update(int done, int total, int objects) {
  if (!enabled_ || total <= 0) return;
  const int percent = static_cast<int>(100.0 * done / total);
  if (percent == last_percent_ && objects == last_objects_) return;
  last_percent_ = percent;
  last_objects_ = objects;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int width = 30, filled = width * done / total;
  std::string extra = s > 0 ? fmt::format(", {:.1f} {}/s", done / s, what_) : "";
  if (objects >= 0) extra += fmt::format(", {} object{} so far", objects, objects == 1 ? "" : "s");
  // \x1b[K clears what a longer earlier line left.
  std::fprintf(stderr, "\r[%s%s] %3d%% %d/%d %s%s\x1b[K", std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), percent, done, total, what_.c_str(),
               extra.c_str());
  std::fflush(stderr);
}

void ProgressBar::Finish() {
  if (enabled_ && last_percent_ >= 0) std::fprintf(stderr, "\n");
}

int FinishRun(const RunInput& input, const PipelineResult& result, const PipelineOptions& options,
              const std::string& out, const StopFlag& stop) {
  auto log = GetLogger("app");
  const RunTrajectories trajectories = BuildRunTrajectories(result.map, input.timestamps);
  const RunMetrics metrics = ComputeRunMetrics(input, result, trajectories, options);
  const RunOutputs outputs = WriteRunOutputs(input, result, trajectories, options, out, &metrics);
  std::printf("%s", SummarizeMetrics(metrics).c_str());
  std::fflush(stdout);
  // The pictures come last: whatever happens to them, the results above are on disk.
  const Timer pictures_timer;
  std::vector<std::string> failed = WriteRunPictures(outputs, result.resources, options, out, &input);
  log->info("pictures and view.html drawn in {:.2f} s", pictures_timer.ElapsedS());
  if (result.renders.failed > 0)
    failed.push_back(std::to_string(result.renders.failed) + " snapshot(s) or overlay(s) during the run");
  for (const std::string& f : failed) log->error("picture not written: {}", f);
  CompleteOutputManifest(out);
  std::printf("outputs: %s\n", out.c_str());
  if (result.error) std::rethrow_exception(result.error);
  if (stop.signal() == SIGINT) return kExitSigint;
  if (stop.signal() == SIGTERM) return kExitSigterm;
  // A run that estimated nothing is a failure a script must see, not a success with empty
  // trajectories; the outputs (log, metrics with run.failed_windows) are written all the same.
  const bool all_failed =
      !result.windows.empty() &&
      std::all_of(result.windows.begin(), result.windows.end(),
                  [](const WindowStats& w) { return w.failed; });
  if (all_failed) {
    log->error("no estimate: all {} backend window(s) were discarded (run.log says why)",
               result.windows.size());
    return kExitNoEstimate;
  }
  if (!failed.empty()) {
    log->error("{} picture(s) not written; metrics.json, the trajectories and the other outputs "
               "are complete", failed.size());
    return kExitOutputError;
  }
  return kExitOk;
}

}  // namespace cslam::apps
