#pragma once
// A plain stereo folder (docs/formats.md "Plain stereo folder"): left/ and right/ PNG images
// paired by file name, an optional times.txt (seconds, one line per pair), and a calibration
// given with --calib (any format ReadRigCalibration reads).
#include <memory>
#include <string>

#include "system/datasets/rig_stereo_source.h"

namespace cslam {

/// Opens the folder. `gt` is a TUM-format trajectory on times.txt's clock ("" = none): of the
/// body frame when the calibration gives one (T_cam_imu), else of cam0. Throws InputError when
/// `calib` is empty, or naming the file for anything missing or malformed.
std::unique_ptr<RigStereoSource> OpenStereoFolder(const std::string& path, const std::string& calib,
                                                  const std::string& gt);

}  // namespace cslam
