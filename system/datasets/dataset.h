#pragma once
// Dataset detection and the one entry point that opens any supported stereo sequence.
#include <memory>
#include <string>

#include "system/datasets/stereo_source.h"

namespace cslam {

/// The kinds of input folders the program understands.
enum class DatasetKind { kKittiRaw, kKittiOdometry, kSynthetic, kAsl, kStereoFolder, kUnknown };

/// Looks at the folder layout only (no file is parsed): image_00/ or image_02/ → KITTI raw;
/// image_0/ with calib.txt → KITTI odometry; observations.csv → synthetic; else kUnknown
/// mav0/cam0 and mav0/cam1 (or cam0/, cam1/) → ASL (EuRoC, TUM-VI); left/ and right/ → plain
/// stereo folder; else kUnknown (also for a missing path or a file).
DatasetKind DetectDataset(const std::string& path);

/// What a user's own rig needs beside its folder.
struct StereoSourceOptions {
  bool color = false;  ///< KITTI raw: the colour pair
  std::string calib;   ///< calibration file ("" = the layout's own; required for a plain folder)
  std::string gt;      ///< TUM-format ground truth ("" = the layout's own, if any)
};

/// Opens a KITTI raw drive or odometry sequence, an ASL sequence or a plain stereo folder
/// (the last two rectified as they are read). Throws InputError when the path is missing,
/// is a synthetic sequence (read by the synthetic reader, not as images) or is none of the
/// known kinds, and whatever the reader throws for bad content.
std::unique_ptr<StereoSource> OpenStereoSource(const std::string& path,
                                               const StereoSourceOptions& options = {});

}  // namespace cslam
