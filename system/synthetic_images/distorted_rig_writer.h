#pragma once
// A synthetic sequence rendered as a user's raw rig records it: each camera rotated by a few tenths of a degree to degrees away from the rectified
// frame and seen through a distorting lens, in the ASL/EuRoC layout with its calibration in
// every format cslam reads, and the ground truth of the body (= the rendered left camera).
// Running cslam on it and on the rectified rendering of the same scene measures what the
// rectification costs (docs/own_rig.md).
#include <string>

#include "system/datasets/stereo_rig.h"
#include "system/synthetic/synthetic_scene.h"
#include "system/synthetic_images/synthetic_renderer.h"

namespace cslam {

/// The raw rig to simulate.
struct DistortedRigOptions {
  LensModel lens = LensModel::kRadialTangential;  ///< radtan or equidistant
  double right_rotation_deg = 2.0;  ///< the right camera's rotation away from the rectified frame
  /// Each raw pixel is the mean of k x k samples over its footprint on a rendering k times
  /// finer, as the rendered images are with SyntheticRenderOptions::supersample = k; in [1, 4].
  int supersample = 3;
  void Check() const;
};

/// Reads the rendered images of the synthetic sequence folder `dir` (WriteSyntheticImages)
/// and writes DIR/rig_<lens>/: mav0/cam{0,1}/{data.csv, data/<ns>.png, sensor.yaml},
/// camchain.yaml (Kalibr), opencv_stereo.yml, orbslam3_settings.yaml, groundtruth_tum.txt
/// (body = rendered left camera; image times are 1 s + the sequence's seconds), and
/// opencv_rectified.yml: the same rig with R1 R2 P1 P2 that rectify back to the rendered camera,
/// with synthetic_truth.txt ("..") so that a run with it is scored on the sequence's truth,
/// objects included (OpenRunInput). The raw images are rendered (with `render`, the options
/// the rectified images were drawn with, except its supersampling): a pinhole view in the
/// rendered camera's frame, options.supersample times finer and wide enough for every raw ray,
/// averaged over each raw pixel's footprint, so the rig's only resampling is the one its
/// rectification makes. The raw focal length is the largest (2 % steps down from the rendered
/// one) at which the raw image sees every rendered pixel.
/// Returns the rig folder. Throws InputError / OutputError naming the file, ConfigError on bad
/// options, cslam::Error when OSMesa fails.
std::string WriteDistortedRig(const SyntheticSequence& sequence, const std::string& dir,
                              const DistortedRigOptions& options, const SyntheticRenderOptions& render);

}  // namespace cslam
