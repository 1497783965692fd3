// `cslam demo`: the embedded default. Generates a short outdoor synthetic sequence with moving
// cars (no data needed), runs the system on it, writes every output and prints the metrics.
#include <cstdio>

#include "apps/command.h"
#include "apps/run_support.h"
#include "core/logging.h"
#include "system/pipeline/run_input.h"
#include "system/run/offscreen_frame_painter.h"
#include "system/synthetic/synthetic_image_io.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"
#include "system/synthetic_images/synthetic_image_writer.h"

namespace cslam::apps {

namespace {

struct DemoArgs {
  std::string out = "out/demo";
  int seed = 1;
  int frames = 150;
  bool no_images = false;
  RunFlags flags;
};

int Demo(const DemoArgs& args) {
  SyntheticOptions synth;
  synth.preset = "outdoor";
  synth.seed = args.seed;
  synth.frames = args.frames;
  synth.Check();
  QuietConsole(args.flags.verbose);
  const std::string sequence_dir = args.out + "/sequence";
  RunInput planned;  // what the manifest records: the sequence the demo is about to write
  planned.path = sequence_dir;
  planned.kind = args.no_images ? InputKind::kSynthetic : InputKind::kSyntheticImages;
  PrepareRunFolder(args.out, "demo", planned, args.flags);
  AttachLogFile(args.out + "/run.log");
  const SyntheticSequence seq = GenerateSynthetic(synth);
  WriteSynthetic(seq, sequence_dir);
  std::printf("demo: generated %s (%d frames, %d landmarks, %d moving cars) in %s\n",
              seq.name.c_str(), seq.num_frames(), seq.observations.num_landmarks(),
              seq.num_objects() - 1, sequence_dir.c_str());
  if (!args.no_images) {
    // The stereo images go through the frontend like a real drive; without them the run
    // replays the generator's tracklets.
    SyntheticRenderOptions render;
    render.texture_period_m = 3.0;
    WriteSyntheticImages(seq, sequence_dir, render);
    std::printf("demo: rendered %d stereo frames %dx%d\n", seq.num_frames(), seq.camera.width,
                seq.camera.height);
  }

  RunInput input = OpenRunInput(sequence_dir, args.flags.InputOptionsFor());
  PipelineOptions options = args.flags.Resolve(input);
  // The demo shows every kind of picture unless told otherwise.
  if (args.flags.snapshots_every < 0) options.output.snapshots_every = 10;
  if (args.flags.overlays_every < 0) options.output.overlays_every = 10;
  options.out_dir = args.out;
  options.painter = std::make_shared<OffscreenFramePainter>();
  PrintRunHeader(input, options, args.out);
  StopFlag stop;
  ProgressBar bar("frames", args.flags.progress);
  PipelineResult result = RunPipeline(input, options, stop.flag(), [&](int done, int total, int objects) {
    bar.Update(done, total, objects);
  });
  bar.Finish();
  const int code = FinishRun(input, result, options, args.out, stop);
  std::printf("images: %s/render/trajectory.png, objects.png", args.out.c_str());
  if (result.renders.snapshots + result.renders.overlays > 0)
    std::printf(", %d snapshots and %d overlays in %s/render/", result.renders.snapshots,
                result.renders.overlays, args.out.c_str());
  std::printf("\n");
  return code;
}

}  // namespace

Command AddDemoCommand(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* sub = app.add_subcommand(
      "demo", "Generate a short outdoor synthetic sequence with moving cars and run the system on it");
  sub->add_option("--out", args->out, "output folder")->capture_default_str();
  sub->add_option("--seed", args->seed, "scene seed")->capture_default_str();
  sub->add_option("--frames", args->frames, "sequence length")->capture_default_str()->check(CLI::Range(30, 2000));
  sub->add_flag("--no-images", args->no_images,
                "replay the generator's tracklets instead of rendering images for the frontend");
  args->flags.Register(sub);
  return {sub, [args] { return Demo(*args); }};
}

}  // namespace cslam::apps
