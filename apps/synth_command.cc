// `cslam synth`: generate a synthetic ground-truth sequence and write it to a folder.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/command.h"
#include "core/timer.h"
#include "system/synthetic_io.h"
#include "system/synthetic_scene.h"

namespace cslam::apps {

Command AddSynthCommand(CLI::App& app) {
  struct Args {
    SyntheticOptions options;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  CLI::App* sub = app.add_subcommand(
      "synth", "Generate a synthetic stereo sequence with ground truth (docs/formats.md)");
  sub->add_option("--preset", args->options.preset, "indoor or outdoor")
      ->check(CLI::IsMember({"indoor", "outdoor"}))
      ->capture_default_str();
  sub->add_option("--seed", args->options.seed, "seed of every random stream")->capture_default_str();
  sub->add_option("--frames", args->options.frames, "number of frames (0: the preset draws)")
      ->capture_default_str();
  sub->add_option("--objects", args->options.objects, "moving objects (-1: the preset draws)")
      ->capture_default_str();
  sub->add_option("--noise-px", args->options.noise_px,
                  "pixel noise: uniform half-width, or sigma with --gaussian (0-3 px)")
      ->capture_default_str();
  sub->add_flag("--gaussian", args->options.gaussian_noise, "Gaussian instead of uniform noise");
  sub->add_option("--landmark-density", args->options.landmark_density,
                  "multiplies the preset's landmark density")
      ->capture_default_str();
  sub->add_option("--out", args->out, "output folder")->required();

  return {sub, [args]() {
            const Timer timer;
            const SyntheticSequence seq = GenerateSynthetic(args->options);
            WriteSynthetic(seq, args->out);
            std::printf(
                "%s: %d frames (%.1f s), %zu landmarks, %zu observations, %d moving objects, "
                "camera travel %.1f m; generated and written to %s in %.2f s.\n",
                seq.name.c_str(), seq.num_frames(), seq.timestamps.back(),
                seq.landmark_object.size(), seq.observations.num_observations(),
                seq.num_objects() - 1, seq.CameraTravel(), args->out.c_str(), timer.ElapsedS());
            return 0;
          }};
}

}  // namespace cslam::apps
