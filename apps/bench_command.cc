// `cslam bench --suite synthetic --out DIR`: the paper's Table 1 protocol on generated
// sequences (system/run/bench_suite.h), written to DIR/bench.json and DIR/bench.md; optional
// sweeps of pixel noise and chunk length with their charts.
// `cslam bench --suite FILE.yaml --out DIR`: a manifest of real drives, synthetic sequences and
// external trajectories (system/run/suite_manifest.h), each run a `cslam run` child process
// (system/run/run_executor.h), gathered into one table (system/run/suite_table.h);
// `cslam bench collect DIR` gathers the table of a suite again.
#include <spdlog/sinks/basic_file_sink.h>

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "apps/command.h"
#include "apps/run_support.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"
#include "system/io/image_io.h"
#include "system/draw/line_chart.h"
#include "system/run/bench_report.h"
#include "system/run/bench_suite.h"
#include "core/atomic_file.h"
#include "system/run/output_folder.h"
#include "system/run/run_executor.h"
#include "system/run/slurm_executor.h"
#include "system/run/suite_manifest.h"
#include "system/run/suite_table.h"

namespace cslam::apps {

namespace {

struct BenchArgs {
  BenchOptions options;
  std::string executor = "local";
  LocalExecutorOptions local;
  SuiteSlurmOptions slurm_flags;  // each set field overrides the manifest's slurm: section
  double slurm_poll_s = 5.0;
  bool slurm_wait = true;
  std::string collect_dir;  // `cslam bench collect DIR`
  double noise_px = -1;  // < 0: the generator's default
  std::vector<std::string> sweeps;
  std::string out = "out/bench";
  bool progress = true;
};

// The sweeps' sequences: the first seed of each preset that the suite has.
std::vector<BenchSequence> SweepSequences(const BenchOptions& o) {
  std::vector<BenchSequence> all = SuiteSequences(o), out;
  for (const std::string preset : {"indoor", "outdoor"})
    for (const BenchSequence& s : all)
      if (s.preset == preset) {
        out.push_back(s);
        break;
      }
  return out;
}

// Every logger writes to `path` only, so the console keeps just the progress bar and summary.
void LogToFileOnly(const std::string& path) {
  auto sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path, true);
  sink->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  const auto def = spdlog::default_logger();
  def->sinks().assign(1, sink);
  spdlog::apply_all([&](const std::shared_ptr<spdlog::logger>& l) {
    if (l != def) l->sinks().assign(1, sink);
  });
}

// OpenCV's Hershey fonts are ASCII only: the charts' names for BenchColumns() keys.
std::string AsciiLabel(const std::string& key) {
  if (key == "accuracy_pct") return "clustering accuracy (%)";
  if (key == "vi") return "VI (nats)";
  if (key == "time_s") return "time (s)";
  return key;
}

// Two charts side by side: column `left` and column `right` of BenchColumns() against x,
// one series per preset.
cv::Mat SweepChart(const BenchSweep& sweep, const std::vector<BenchSequence>& sequences,
                   const std::vector<std::string>& column_keys) {
  std::vector<cv::Mat> panels;
  for (const std::string& key : column_keys) {
    size_t col = 0;
    while (BenchColumns()[col].key != key) ++col;
    LineChart chart;
    chart.title = AsciiLabel(key) + " vs " + sweep.x_label + ", Ours";
    chart.x_label = sweep.x_label;
    chart.y_label = AsciiLabel(key);
    for (size_t k = 0; k < sequences.size(); ++k) {
      ChartSeries series;
      series.label = sequences[k].preset + " seed " + std::to_string(sequences[k].seed);
      series.color_bgr = SeriesColor(static_cast<int>(k));
      for (size_t i = 0; i < sweep.x.size(); ++i) {
        if (k >= sweep.entries[i].size() || !sweep.entries[i][k].ok) continue;
        if (const auto v = BenchColumns()[col].value(sweep.entries[i][k].metrics)) {
          series.x.push_back(sweep.x[i]);
          series.y.push_back(*v);
        }
      }
      chart.series.push_back(series);
    }
    if (key == "accuracy_pct") chart.y_max = 100;
    if (key != "log_chi2") chart.y_min = 0;
    panels.push_back(RenderLineChart(chart, 800, 560));
  }
  cv::Mat out;
  cv::hconcat(panels, out);
  return out;
}

int BenchSynthetic(BenchArgs& args) {
  if (args.noise_px >= 0) args.options.noise_px = args.noise_px;
  args.options.Check();
  for (const std::string& s : args.sweeps)
    if (s != "noise" && s != "chunk")
      throw ConfigError("--sweep: unknown sweep '" + s + "' (known: noise, chunk)");
  const BenchOptions& o = args.options;
  const std::vector<BenchSequence> sequences = SuiteSequences(o);
  BenchReport report;
  report.options = o;
  report.methods = o.SelectedMethods();

  CreateWritableFolder(args.out);
  LogToFileOnly(args.out + "/bench.log");
  auto log = GetLogger("app");

  // Sweep plans: x values and the options of each point.
  const std::vector<BenchSequence> sweep_sequences = SweepSequences(o);
  const std::vector<double> noise_values = {0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0};
  const std::vector<double> chunk_values = {30, 60, 100, 150, 200, 300};
  int total = static_cast<int>(sequences.size() * report.methods.size());
  for (const std::string& s : args.sweeps)
    total += static_cast<int>(sweep_sequences.size() *
                              (s == "noise" ? noise_values.size() : chunk_values.size()));
  log->info("bench: suite {}, {} sequences × {} methods, {} runs in all, frames {}", o.suite,
            sequences.size(), report.methods.size(), total, o.frames);

  const Timer timer;
  StopFlag stop;
  ProgressBar bar("runs", args.progress);
  int done = 0;
  auto save = [&] {
    report.total_s = timer.ElapsedS();
    report.interrupted = stop.signal() != 0;
    WriteBenchReport(report, args.out);
    spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& l) { l->flush(); });
  };
  bar.Update(0, total);
  for (const BenchSequence& seq : sequences) {
    if (stop.signal()) break;
    const RunInput input = GenerateBenchInput(seq, o.frames);
    for (const BenchMethod& m : report.methods) {
      if (stop.signal()) break;
      report.entries.push_back(
          RunBenchEntry(input, seq, m, BenchPipelineOptions(seq.preset, m), stop.flag()));
      bar.Update(++done, total);
    }
    save();  // after every sequence, so an interrupted bench keeps what it finished
  }

  const BenchMethod& ours = FindBenchMethod("clusterslam");
  for (const std::string& name : args.sweeps) {
    const std::vector<double>& xs = name == "noise" ? noise_values : chunk_values;
    // Filled point by point and saved after each, so an interrupted sweep keeps what finished.
    BenchSweep& sweep = report.sweeps.emplace_back();
    sweep.name = name;
    sweep.x_label = name == "noise" ? "pixel noise (px)" : "chunk length (frames)";
    const std::vector<std::string> columns =
        name == "noise" ? std::vector<std::string>{"accuracy_pct", "vi"}
                        : std::vector<std::string>{"vi", "time_s"};
    for (double x : xs) {
      if (stop.signal()) break;
      std::vector<BenchEntry> point;
      for (BenchSequence seq : sweep_sequences) {
        if (stop.signal()) break;
        if (name == "noise") seq.noise_px = x;
        const int chunk = name == "chunk" ? static_cast<int>(x) : 0;
        const RunInput input = GenerateBenchInput(seq, o.frames);
        point.push_back(RunBenchEntry(input, seq, ours, BenchPipelineOptions(seq.preset, ours, chunk),
                                      stop.flag()));
        bar.Update(++done, total);
      }
      sweep.x.push_back(x);
      sweep.entries.push_back(std::move(point));
      WritePng(SweepChart(sweep, sweep_sequences, columns), args.out + "/sweep_" + name + ".png");
      save();
    }
  }
  bar.Finish();
  save();

  std::vector<const BenchEntry*> all;
  for (const BenchEntry& e : report.entries) all.push_back(&e);
  for (const BenchSweep& s : report.sweeps)
    for (const auto& point : s.entries)
      for (const BenchEntry& e : point) all.push_back(&e);
  int failed = 0;
  for (const BenchEntry* e : all) failed += !e->ok;
  std::printf("bench: %d runs (%d failed) in %.0f s; wrote %s/bench.json and %s/bench.md\n",
              done, failed, report.total_s, args.out.c_str(), args.out.c_str());
  for (const BenchEntry* e : all)
    if (!e->ok)
      std::printf("  failed: %s × %s: %s\n", e->sequence.c_str(), e->method.label.c_str(),
                  e->error.c_str());
  if (stop.signal() == SIGINT) return kExitSigint;
  if (stop.signal() == SIGTERM) return kExitSigterm;
  return kExitOk;
}


namespace fs = std::filesystem;

// This program's own path, for the child processes (argv[0] may be relative or on PATH).
std::string OwnProgramPath() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw ConfigError("cannot find this program's path (/proc/self/exe): " + ec.message());
  return p.string();
}

// A manifest is named by its file: FILE.yaml / FILE.yml, or any existing file.
bool IsManifest(const std::string& suite) {
  const std::string ext = fs::path(suite).extension().string();
  std::error_code ec;
  return ext == ".yaml" || ext == ".yml" || fs::is_regular_file(suite, ec);
}

// DIR/suite.json: what `cslam bench collect DIR` needs to find the manifest again.
void WriteSuiteRecord(const SuiteManifest& manifest, const std::string& executor,
                      const std::string& out) {
  const nlohmann::json j = {{"manifest", manifest.file}, {"executor", executor}};
  WriteFileAtomically((fs::path(out) / "suite.json").string(),
                      [&](std::ostream& o) { o << j.dump(2) << "\n"; });
}

// Prints the table's summary; the exit code: non-zero when no row succeeded.
int SummariseSuite(const SuiteTable& table, const std::string& out) {
  int ok = 0;
  for (const SuiteRow& r : table.rows) ok += r.status == "ok";
  std::printf("bench: %zu rows: %d ok, %d failed, %d incomplete in %.0f s; wrote %s/bench.json, "
              "bench.md and bench.png\n",
              table.rows.size(), ok, table.Failed(), table.Incomplete(), table.total_s, out.c_str());
  for (const SuiteRow& r : table.rows)
    if (r.status == "failed") std::printf("  failed: %s: %s\n", r.id.c_str(), r.error.c_str());
  if (ok == 0) {
    std::fprintf(stderr, "cslam bench: error: every run of the suite failed or is incomplete\n");
    return kExitNoEstimate;
  }
  return kExitOk;
}

int BenchSuiteManifest(BenchArgs& args) {
  args.local.Check();
  if (args.executor != "local" && args.executor != "slurm")
    throw ConfigError("--executor: unknown executor '" + args.executor + "' (known: local, slurm)");
  SuiteManifest manifest = ReadSuiteManifest(args.options.suite);
  SlurmExecutorOptions slurm;
  slurm.resources = manifest.slurm;
  if (!args.slurm_flags.partition.empty()) slurm.resources.partition = args.slurm_flags.partition;
  if (!args.slurm_flags.time.empty()) slurm.resources.time = args.slurm_flags.time;
  if (!args.slurm_flags.mem.empty()) slurm.resources.mem = args.slurm_flags.mem;
  if (!args.slurm_flags.account.empty()) slurm.resources.account = args.slurm_flags.account;
  if (args.slurm_flags.cpus_per_task > 0) slurm.resources.cpus_per_task = args.slurm_flags.cpus_per_task;
  slurm.poll_s = args.slurm_poll_s;
  slurm.wait = args.slurm_wait;
  slurm.Check();
  const std::string program = OwnProgramPath();
  CreateWritableFolder(args.out);
  LogToFileOnly(args.out + "/bench.log");
  auto log = GetLogger("app");
  log->info("bench: suite {}: {} runs, {} external trajectories, executor {}", manifest.file,
            manifest.runs.size(), manifest.externals.size(), args.executor);
  WriteSuiteRecord(manifest, args.executor, args.out);
  PrepareSyntheticInputs(manifest, args.out);

  // External trajectories first: a bad file is reported before hours of runs.
  for (const SuiteExternal& x : manifest.externals) {
    const SuiteRow row = ScoreExternalRow(x);
    if (row.status != "ok") std::printf("bench: external %s failed: %s\n", x.id.c_str(), row.error.c_str());
  }

  std::vector<RunTask> tasks;
  const std::string runs = SuiteRunsFolder(args.out);
  for (const SuiteRun& r : manifest.runs) {
    RunTask t;
    t.id = r.id;
    t.dir = (fs::absolute(runs) / r.id).lexically_normal().string();
    t.argv = {program};
    for (std::string& a : r.RunArguments(r.input, t.dir)) t.argv.push_back(std::move(a));
    tasks.push_back(std::move(t));
  }

  const Timer timer;
  StopFlag stop;
  const bool tty = args.progress && isatty(2);
  int last_done = -1;
  const auto on_progress = [&](const SuiteProgress& p) {
    if (tty) {
      std::fprintf(stderr, "\r%s   ", p.Line().c_str());
      std::fflush(stderr);
    } else if (p.done != last_done) {
      std::fprintf(stderr, "%s\n", p.Line().c_str());
    }
    if (p.done != last_done) log->info("{}", p.Line());
    last_done = p.done;
  };
  if (args.executor == "slurm") {
    const std::string job = RunOnSlurm(tasks, slurm, args.out, stop.flag(), on_progress);
    if (!slurm.wait) {
      std::printf("bench: submitted Slurm array job %s; when it has ended: cslam bench collect %s\n",
                  job.c_str(), args.out.c_str());
      return kExitOk;
    }
  } else {
    RunLocally(tasks, args.local, stop.flag(), on_progress);
  }
  if (tty) std::fprintf(stderr, "\n");

  SuiteTable table = CollectSuiteTable(manifest, args.out);
  table.executor = args.executor;
  table.total_s = timer.ElapsedS();
  table.interrupted = stop.signal() != 0;
  WriteSuiteTable(table, args.out);
  spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& l) { l->flush(); });
  const int code = SummariseSuite(table, args.out);
  if (stop.signal() == SIGINT) return kExitSigint;
  if (stop.signal() == SIGTERM) return kExitSigterm;
  return code;
}

int BenchCollect(const BenchArgs& args) {
  const std::string record = (fs::path(args.collect_dir) / "suite.json").string();
  std::ifstream in(record);
  if (!in) throw InputError(record, "not found: is " + args.collect_dir + " the --out folder of a `cslam bench --suite FILE.yaml`?");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw InputError(record, std::string("not valid JSON: ") + e.what());
  }
  if (!j.contains("manifest") || !j["manifest"].is_string())
    throw InputError(record, "has no \"manifest\" string");
  SuiteManifest manifest = ReadSuiteManifest(j["manifest"].get<std::string>());
  PrepareSyntheticInputs(manifest, args.collect_dir);
  const Timer timer;
  SuiteTable table = CollectSuiteTable(manifest, args.collect_dir);
  table.executor = j.value("executor", std::string("local"));
  table.total_s = timer.ElapsedS();
  WriteSuiteTable(table, args.collect_dir);
  return SummariseSuite(table, args.collect_dir);
}

int Bench(BenchArgs& args) {
  if (!args.collect_dir.empty()) return BenchCollect(args);
  if (IsManifest(args.options.suite)) return BenchSuiteManifest(args);
  return BenchSynthetic(args);
}

}  // namespace

Command AddBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* sub = app.add_subcommand(
      "bench", "Run every backend method on a generated synthetic suite (the paper's Table 1) "
               "and write bench.json and bench.md");
  sub->add_option("--suite", args->options.suite,
                  "`synthetic` (generated sequences, in this process) or a suite manifest "
                  "FILE.yaml (docs/usage.md): each run a `cslam run` child process")
      ->capture_default_str();
  sub->add_option("--executor", args->executor,
                  "with a manifest: local (a pool of processes here) or slurm (one sbatch array "
                  "job, each task one run)")
      ->capture_default_str();
  sub->add_option("--slurm-partition", args->slurm_flags.partition, "sbatch --partition");
  sub->add_option("--slurm-time", args->slurm_flags.time, "sbatch --time per task, e.g. 01:00:00");
  sub->add_option("--slurm-mem", args->slurm_flags.mem, "sbatch --mem per task, e.g. 4G");
  sub->add_option("--slurm-cpus", args->slurm_flags.cpus_per_task, "sbatch --cpus-per-task");
  sub->add_option("--slurm-account", args->slurm_flags.account, "sbatch --account");
  sub->add_option("--slurm-poll", args->slurm_poll_s, "seconds between squeue polls")
      ->capture_default_str();
  sub->add_flag("!--no-wait", args->slurm_wait,
                "with --executor slurm: submit and return; `cslam bench collect DIR` later");
  sub->add_option("--jobs", args->local.jobs, "with --executor local: runs at once")
      ->capture_default_str();
  sub->add_option("--out", args->out, "output folder")->capture_default_str();
  sub->add_option("--frames", args->options.frames,
                  "cap every sequence to its first N frames (0: whole sequences)")
      ->capture_default_str();
  sub->add_option("--seeds-indoor", args->options.seeds_indoor, "indoor sequences (seeds 1..K)")
      ->capture_default_str();
  sub->add_option("--seeds-outdoor", args->options.seeds_outdoor, "outdoor sequences (seeds 1..K)")
      ->capture_default_str();
  sub->add_option("--methods", args->options.methods,
                  "comma-separated: full-ba, pdcs, clusterslam-no-u, clusterslam-no-i, "
                  "clusterslam, true-labels (default: the paper's five, all but true-labels)")
      ->delimiter(',');
  sub->add_option("--noise", args->noise_px, "generator pixel noise, px (default: the generator's)")
      ->check(CLI::Range(0.0, 3.0));
  sub->add_option("--sweep", args->sweeps,
                  "also sweep `noise` (0-3 px) or `chunk` (chunk length 30-300) with Ours on "
                  "the first indoor and outdoor sequence; repeatable")
      ->delimiter(',');
  sub->add_flag("!--no-progress", args->progress, "no progress bar");
  CLI::App* collect = sub->add_subcommand(
      "collect", "Gather the table (bench.json, bench.md, bench.png) of a suite's --out folder "
                 "again, e.g. after its Slurm job ended");
  collect->add_option("dir", args->collect_dir, "the suite's output folder")->required();
  return {sub, [args] { return Bench(*args); }};
}

}  // namespace cslam::apps
