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
#include "system/run/run_metrics.h"
#include "system/run/run_trajectories.h"
#include "system/run/run_writer.h"

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
  sub->add_option("--snapshots-every", snapshots_every, "render a snapshot every N frames (0: off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--overlays-every", overlays_every, "render a keypoint overlay every N frames (0: off)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--max-frames", max_frames, "process only the first N frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--cameras", cameras, "KITTI raw: grey (image_00/01) or color (image_02/03)")
      ->check(CLI::IsMember({"grey", "color"}));
  sub->add_flag("!--no-progress", progress, "no progress bar");
}

InputOptions RunFlags::InputOptionsFor() const {
  InputOptions o;
  o.color = cameras == "color";
  o.max_frames = max_frames;
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
  o.input = InputOptionsFor();
  o.Check();
  return o;
}

void PrepareOutputFolder(const std::string& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw OutputError(out, "cannot create the output folder" + (ec ? ": " + ec.message() : ""));
  const fs::path probe = fs::path(out) / ".cslam_write_test";
  {
    std::ofstream f(probe);
    if (!f) throw OutputError(out, "the output folder is not writable");
  }
  fs::remove(probe, ec);
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

void ProgressBar::Update(int done, int total) {
  if (!enabled_ || total <= 0) return;
  const int percent = static_cast<int>(100.0 * done / total);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  const int width = 40, filled = width * done / total;
  std::fprintf(stderr, "\r[%s%s] %3d%% %d/%d %s", std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), percent, done, total, what_.c_str());
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
  WriteRunOutputs(input, result, trajectories, options, out, &metrics);
  std::printf("%s\n", SummarizeMetrics(metrics).c_str());
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
  return kExitOk;
}

}  // namespace cslam::apps
