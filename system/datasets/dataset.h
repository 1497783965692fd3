#pragma once
// Dataset detection and the one entry point that opens any supported stereo sequence.
#include <memory>
#include <string>

#include "system/datasets/stereo_source.h"

namespace cslam {

/// The kinds of input folders the program understands.
enum class DatasetKind { kKittiRaw, kKittiOdometry, kSynthetic, kUnknown };

/// Looks at the folder layout only (no file is parsed): image_00/ or image_02/ → KITTI raw;
/// image_0/ with calib.txt → KITTI odometry; observations.csv → synthetic; else kUnknown
/// (also for a missing path or a file).
DatasetKind DetectDataset(const std::string& path);

/// Opens a KITTI raw drive or odometry sequence. Throws InputError when the path is missing,
/// is a synthetic sequence (read by the synthetic reader, not as images) or is none of the
/// known kinds, and whatever the reader throws for bad content.
std::unique_ptr<StereoSource> OpenStereoSource(const std::string& path, bool color = false);

}  // namespace cslam
