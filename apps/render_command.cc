// `cslam render OUT`: draws the pictures of a finished run again from its output files
// (system/run/run_outputs_reader.h) and the input its cslam_outputs.json records, with the
// same functions the run itself used.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/command.h"
#include "core/errors.h"
#include "core/logging.h"
#include "system/io/image_io.h"
#include "system/pipeline/pipeline_options.h"
#include "system/pipeline/run_input.h"
#include "system/run/final_pictures.h"
#include "system/run/object_track_plot.h"
#include "system/run/output_folder.h"
#include "system/run/resource_chart.h"
#include "system/run/run_outputs_reader.h"
#include "system/run/run_trajectory_plot.h"

namespace cslam::apps {

namespace {

struct RenderArgs {
  std::string out;
  int width = 1200, height = 900;  // RenderTrajectoryTopView's defaults, as the run uses
};

// The input a run recorded, opened again for the final-state pictures (its camera and
// images). Throws InputError naming the manifest or the input when either is gone.
RunInput ReopenRecordedInput(const std::string& out) {
  const OutputManifest m = ReadOutputManifest(out);
  InputOptions o;
  o.color = m.input.cameras == "color";
  o.max_frames = m.input.max_frames;
  o.use_images = m.input.kind != NameOf(kInputKindNames, InputKind::kSynthetic);
  return OpenRunInput(m.input.path, o);
}

// How many final-state frames the run drew (its config.yaml), else the default.
int FinalPictureCount(const std::string& out) {
  try {
    return LoadPipelineOptions(Preset::kOutdoor, (std::filesystem::path(out) / "config.yaml").string())
        .output.final_pictures;
  } catch (const Error&) {
    return OutputOptions{}.final_pictures;
  }
}

int Render(const RenderArgs& args) {
  auto log = GetLogger("app");
  // Everything is read before anything is replaced, so a bad output folder leaves the old
  // pictures (or none) in place.
  const RunOutputs outputs = ReadRunOutputs(args.out);
  log->info("{}: camera trajectory of {} poses{}, {} moving clusters, {} landmarks", args.out,
            outputs.camera.size(), outputs.gt_camera.empty() ? "" : " with ground truth",
            outputs.clusters.size(), outputs.landmarks.size());
  std::vector<ResourceSample> samples;
  const std::filesystem::path resources = std::filesystem::path(args.out) / "resources.csv";
  if (std::filesystem::exists(resources)) samples = ReadResourceLog(resources.string());
  const cv::Mat plot = RenderRunTrajectoryPlot(outputs, args.width, args.height);
  const std::string path = (std::filesystem::path(args.out) / "render" / "trajectory.png").string();
  WritePng(plot, path);
  std::printf("%s\n", path.c_str());
  std::printf("%s\n", WriteObjectTrackPlot(outputs, args.out, args.width, args.height).c_str());
  if (samples.size() >= 2) {
    WriteResourceChart(samples, args.out);
    std::printf("%s\n", (std::filesystem::path(args.out) / "render" / "resources.png").c_str());
  }
  // The snapshots and overlays need the input's camera and images, found through the manifest.
  const RunInput input = ReopenRecordedInput(args.out);
  const std::string render_dir = (std::filesystem::path(args.out) / "render").string();
  const std::vector<int> frames = SpreadFrames(outputs.camera.frames, FinalPictureCount(args.out));
  const std::vector<std::string> failed =
      WriteFinalPictures(outputs, frames, input.camera, input.images.get(), render_dir);
  for (const std::string& f : failed) log->error("picture not written: render/{}", f);
  std::printf("%zu final snapshot(s) and %zu overlay(s) in %s\n", frames.size(),
              input.has_images() ? outputs.keypoints.size() : 0, render_dir.c_str());
  return failed.empty() ? kExitOk : kExitOutputError;
}

}  // namespace

Command AddRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* sub = app.add_subcommand(
      "render", "Draw the pictures of a finished run again from its output files (and the "
                "input recorded in them)");
  sub->add_option("out", args->out, "output folder of `cslam run` or `cslam demo`")->required();
  sub->add_option("--width", args->width, "picture width, px")
      ->capture_default_str()
      ->check(CLI::Range(200, 8000));
  sub->add_option("--height", args->height, "picture height, px")
      ->capture_default_str()
      ->check(CLI::Range(150, 8000));
  return {sub, [args] { return Render(*args); }};
}

}  // namespace cslam::apps
