// `cslam calib check INPUT [--calib FILE]`: does the calibration rectify these images? Writes a
// rectified pair side by side with horizontal lines and prints the vertical offsets of stereo
// matches, the baseline and the focal length; exits 1 with the likely mistake when it does not.
#include <cstdio>
#include <filesystem>

#include "apps/command.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/datasets/dataset.h"
#include "system/datasets/rig_image_check.h"
#include "system/io/image_io.h"

namespace cslam::apps {

namespace {

struct CalibArgs {
  std::string input, calib, out;
  int pairs = 5;
};

int RunCheck(const CalibArgs& args) {
  StereoSourceOptions options;
  options.calib = args.calib;
  const std::unique_ptr<StereoSource> source = OpenStereoSource(args.input, options);
  const std::string out = args.out.empty() ? "out/" + source->name() : args.out;
  std::vector<int> frames;
  const int n = source->size(), k = std::max(1, std::min(args.pairs, n));
  for (int i = 0; i < k; ++i) frames.push_back(k == 1 ? 0 : i * (n - 1) / (k - 1));
  const RigImageCheck check = CheckRigOnImages(*source, frames);

  const StereoFrame shown = source->Load(frames[frames.size() / 2]);
  const std::string png = out + "/calib_check.png";
  WritePng(SideBySideWithLines(shown.left, shown.right), png);
  for (const auto& file : source->DescriptionFiles())
    WriteFileAtomically(out + "/" + file.first, [&](std::ostream& s) { s << file.second; });

  const StereoCamera& cam = source->camera();
  std::printf("%s (%s): %d pairs %dx%d\n", source->name().c_str(), source->kind().c_str(), n, cam.width,
              cam.height);
  std::printf("  rectified focal length  %10.2f px (cx %.2f, cy %.2f)\n", cam.fx, cam.cx, cam.cy);
  std::printf("  baseline                %10.4f m\n", cam.baseline);
  std::printf("  vertical offset of %4d stereo matches in %d pairs, rectified: median %.2f px, "
              "90th percentile %.2f px\n",
              check.rectified.matches, k, check.rectified.median, check.rectified.p90);
  if (check.raw.matches > 0)
    std::printf("  the same pairs as recorded (%d matches):  median %.2f px, 90th percentile %.2f px\n",
                check.raw.matches, check.raw.median, check.raw.p90);
  std::printf("  picture: %s (pair %d, green lines every 24 rows)\n", png.c_str(), shown.index);
  if (!check.ok) throw InputError(args.input, check.problem);
  std::printf("  OK: rows agree (median <= %.1f px)\n", kMaxMedianVerticalOffsetPx);
  return kExitOk;
}

}  // namespace

Command AddCalibCommand(CLI::App& app) {
  auto args = std::make_shared<CalibArgs>();
  CLI::App* calib = app.add_subcommand("calib", "Check a stereo rig's calibration on its images");
  calib->require_subcommand(1);
  CLI::App* check = calib->add_subcommand(
      "check", "Rectify a few pairs, measure the vertical offsets of stereo matches, write a picture");
  check->add_option("input", args->input, "input folder (ASL/EuRoC, plain left/ right/, KITTI)")->required();
  check->add_option("--calib", args->calib, "calibration file (Kalibr, OpenCV, ORB-SLAM3)");
  check->add_option("--out", args->out, "where calib_check.png goes (default: out/<sequence name>)");
  check->add_option("--pairs", args->pairs, "pairs to check, spread over the sequence")
      ->check(CLI::PositiveNumber);
  return {calib, [args] { return RunCheck(*args); }};
}

}  // namespace cslam::apps
