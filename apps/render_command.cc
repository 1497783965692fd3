// `cslam render OUT`: draws the pictures of a finished run again from its output files
// (system/run/run_outputs_reader.h), with the same functions the run itself used.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/command.h"
#include "core/logging.h"
#include "system/io/image_io.h"
#include "system/run/resource_chart.h"
#include "system/run/run_outputs_reader.h"
#include "system/run/run_trajectory_plot.h"

namespace cslam::apps {

namespace {

struct RenderArgs {
  std::string out;
  int width = 1200, height = 900;  // RenderTrajectoryTopView's defaults, as the run uses
};

int Render(const RenderArgs& args) {
  auto log = GetLogger("app");
  // Everything is read and drawn before the one file is replaced, so a bad output folder
  // leaves the old picture (or none) in place.
  const RunOutputs outputs = ReadRunOutputs(args.out);
  log->info("{}: camera trajectory of {} poses{}, {} moving clusters, {} landmarks", args.out,
            outputs.camera.size(), outputs.gt_camera.empty() ? "" : " with ground truth",
            outputs.clusters.size(), outputs.landmarks.size());
  const cv::Mat plot = RenderRunTrajectoryPlot(outputs, args.width, args.height);
  const std::string path = (std::filesystem::path(args.out) / "render" / "trajectory.png").string();
  WritePng(plot, path);
  std::printf("%s\n", path.c_str());
  const std::filesystem::path resources = std::filesystem::path(args.out) / "resources.csv";
  if (std::filesystem::exists(resources)) {
    const std::vector<ResourceSample> samples = ReadResourceLog(resources.string());
    if (samples.size() >= 2) {
      const std::string chart = (std::filesystem::path(args.out) / "render" / "resources.png").string();
      WritePng(RenderResourceChart(samples), chart);
      std::printf("%s\n", chart.c_str());
    }
  }
  // Overlays draw each frame's tracked keypoints on its left image; a run keeps neither.
  log->info("render/overlay_*.png not re-rendered: the per-frame keypoint tracks are not among "
            "a run's outputs");
  return 0;
}

}  // namespace

Command AddRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* sub = app.add_subcommand(
      "render", "Re-render render/trajectory.png of a finished run from its output files");
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
