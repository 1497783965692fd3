// `cslam run INPUT`: the whole system over a KITTI raw drive, a KITTI odometry sequence or a
// synthetic sequence, writing every output of docs/architecture.md into --out.
#include <spdlog/sinks/basic_file_sink.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>

#include "apps/command.h"
#include "apps/run_support.h"
#include "core/errors.h"
#include "core/logging.h"
#include "system/pipeline/pipeline.h"
#include "system/pipeline/run_input.h"
#include "system/run/offscreen_frame_painter.h"
#include "system/run/run_metrics.h"
#include "system/run/run_writer.h"

namespace cslam::apps {

namespace {

struct RunArgs {
  std::string input;
  std::string out;
  RunFlags flags;
};

int Run(const RunArgs& args) {
  QuietConsole(args.flags.verbose);
  RunInput input = OpenRunInput(args.input, args.flags.InputOptionsFor());
  PipelineOptions options = args.flags.Resolve(input);
  CheckMethodFitsInput(options.method, input);
  const std::string out = args.out.empty() ? "out/" + input.name : args.out;
  options.out_dir = out;
  options.painter = std::make_shared<OffscreenFramePainter>();
  // The output folder is created only once the input and the configuration are known good.
  PrepareRunFolder(out, "run", input, args.flags);
  AttachLogFile(out + "/run.log");
  PrintRunHeader(input, options, out);

  StopFlag stop;
  ProgressBar bar("frames", args.flags.progress);
  PipelineResult result = RunPipeline(input, options, stop.flag(), [&](int done, int total, int objects) {
    bar.Update(done, total, objects);
  });
  bar.Finish();
  return FinishRun(input, result, options, out, stop);
}

}  // namespace

Command AddRunCommand(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand(
      "run", "Run the system over a KITTI raw drive, a KITTI odometry sequence or a synthetic "
             "sequence folder");
  sub->add_option("input", args->input, "input folder")->required();
  sub->add_option("--out", args->out, "output folder (default: out/<sequence name>)");
  args->flags.Register(sub);
  return {sub, [args] { return Run(*args); }};
}

}  // namespace cslam::apps
