// `cslam run INPUT`: the whole system over a KITTI raw drive, a KITTI odometry sequence, a
// user's own rig (ASL/EuRoC layout or a plain folder) or a synthetic sequence, writing every
// output of docs/architecture.md into --out.
#include <spdlog/sinks/basic_file_sink.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>

#include "apps/command.h"
#include "apps/run_support.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/rig_image_check.h"
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
  std::string calib, gt;
  RunFlags flags;
};

int Run(const RunArgs& args) {
  QuietConsole(args.flags.verbose);
  auto log = GetLogger("app");
  InputOptions input_options = args.flags.InputOptionsFor();
  input_options.calib = args.calib;
  input_options.gt = args.gt;
  RunInput input = OpenRunInput(args.input, input_options);
  if (!input.description_files.empty()) {
    // A user's rig: refuse it before anything runs when the first pair shows it is not
    // rectified. A first pair too dark or bare to measure (a lens cap) proves nothing.
    const RigImageCheck check = CheckRigOnImages(*input.images, {0});
    if (!check.ok && check.measured)
      throw InputError(args.input, check.problem + " (cslam calib check shows the rectified pair)");
    if (!check.ok) log->warn("the rig's rows could not be checked on the first pair: {}", check.problem);
  }
  PipelineOptions options = args.flags.Resolve(input);
  CheckMethodFitsInput(options.method, input);
  const std::string out = args.out.empty() ? "out/" + input.name : args.out;
  options.out_dir = out;
  options.painter = std::make_shared<OffscreenFramePainter>();
  // The output folder is created only once the input and the configuration are known good.
  PrepareRunFolder(out, "run", input, args.flags);
  AttachLogFile(out + "/run.log");
  for (const auto& file : input.description_files)
    WriteFileAtomically(out + "/" + file.first, [&](std::ostream& s) { s << file.second; });
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
      "run", "Run the system over a KITTI raw drive, a KITTI odometry sequence, an ASL/EuRoC "
             "sequence, a plain left/ right/ folder (--calib) or a synthetic sequence folder");
  sub->add_option("input", args->input, "input folder")->required();
  sub->add_option("--out", args->out, "output folder (default: out/<sequence name>)");
  sub->add_option("--calib", args->calib,
                  "stereo calibration (Kalibr camchain, OpenCV, ORB-SLAM3); required for a plain "
                  "left/ right/ folder, overrides an ASL sequence's sensor.yaml");
  sub->add_option("--gt", args->gt, "ground truth of the body frame in TUM format (t x y z qx qy qz qw)");
  args->flags.Register(sub);
  return {sub, [args] { return Run(*args); }};
}

}  // namespace cslam::apps
