// `cslam synth`: generate a synthetic ground-truth sequence and write it to a folder.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/command.h"
#include "core/timer.h"
#include "system/synthetic/synthetic_image_io.h"
#include "core/errors.h"
#include "system/synthetic_images/distorted_rig_writer.h"
#include "system/synthetic_images/synthetic_image_writer.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam::apps {

Command AddSynthCommand(CLI::App& app) {
  struct Args {
    SyntheticOptions options;
    std::string out;
    bool images = false;
    SyntheticRenderOptions render;
    double texture_period_m = 0;  // 0: the preset's
    std::vector<std::string> rigs;  // lens models of distorted raw rigs to write
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
  CLI::Option* baseline =
      sub->add_option("--baseline", args->options.baseline_m,
                      "stereo baseline, m (0: the preset's, 0.50 outdoor, 0.10 indoor; with --rig "
                      "0.12, the issue-37 rig); the scene is the same for any baseline")
          ->check(CLI::Range(0.0, 2.0))
          ->capture_default_str();
  sub->add_option("--out", args->out, "output folder")->required();
  sub->add_flag("--images", args->images,
                "also render the stereo images and object ids (KITTI odometry layout under "
                "sequences/00, poses/00.txt)");
  sub->add_option("--texture-period", args->texture_period_m,
                  "with --images: metres one texture tile spans (0: 3 outdoor, 1 indoor)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  CLI::Option* supersample =
      sub->add_option("--supersample", args->render.supersample,
                      "with --images: render k times larger and filter down (1-4; with --rig 3, "
                      "which the raw images are drawn with too)")
          ->check(CLI::Range(1, 4))
          ->capture_default_str();
  sub->add_option("--grey-noise", args->render.grey_noise,
                  "with --images: add uniform integer noise in [-n, n] grey levels to the rectified "
                  "images (a perturbation to measure how much results move; 0-20)")
      ->check(CLI::Range(0, 20))
      ->capture_default_str();
  sub->add_option("--grey-noise-seed", args->render.grey_noise_seed, "seeds --grey-noise")
      ->capture_default_str();
  sub->add_option("--rig", args->rigs,
                  "with --images: also write the images as a distorted raw rig records them "
                  "(radtan and/or equidistant): DIR/rig_<lens>/, ASL layout, calibration in "
                  "every format, body ground truth (docs/own_rig.md)")
      ->check(CLI::IsMember({"radtan", "equidistant"}));

  return {sub, [args, baseline, supersample]() {
            // A rig and the rectified rendering it is compared with share one pixel model
            // (k x k samples per pixel) and the rig baseline unless told otherwise.
            if (!args->rigs.empty()) {
              if (baseline->count() == 0) args->options.baseline_m = 0.12;
              if (supersample->count() == 0) args->render.supersample = 3;
            }
            const Timer timer;
            const SyntheticSequence seq = GenerateSynthetic(args->options);
            WriteSynthetic(seq, args->out);
            const double written_s = timer.ElapsedS();
            std::printf(
                "%s: %d frames (%.1f s), %zu landmarks, %zu observations, %d moving objects, "
                "camera travel %.1f m, baseline %.2f m; generated and written to %s in %.2f s.\n",
                seq.name.c_str(), seq.num_frames(), seq.timestamps.back(),
                seq.landmark_object.size(), seq.observations.num_observations(),
                seq.num_objects() - 1, seq.CameraTravel(), seq.camera.baseline, args->out.c_str(), written_s);
            if (args->images) {
              const Timer render_timer;
              SyntheticRenderOptions render = args->render;
              render.texture_period_m = args->texture_period_m > 0 ? args->texture_period_m
                                        : args->options.preset == "indoor" ? 1.0
                                                                            : 3.0;
              WriteSyntheticImages(seq, args->out, render);
              std::printf("rendered %d stereo frames %dx%d with object ids into %s in %.2f s.\n",
                          seq.num_frames(), seq.camera.width, seq.camera.height,
                          SyntheticImagesDir(args->out).c_str(), render_timer.ElapsedS());
              for (const std::string& lens : args->rigs) {
                DistortedRigOptions rig;
                rig.lens = ParseEnum(kLensModelNames, lens, "--rig");
                rig.supersample = render.supersample;
                std::printf("distorted %s rig: %s\n", lens.c_str(),
                            WriteDistortedRig(seq, args->out, rig, render).c_str());
              }
            } else if (!args->rigs.empty()) {
              throw ConfigError("--rig", "needs --images (the rig is made from the rendered images)");
            }
            return 0;
          }};
}

}  // namespace cslam::apps
