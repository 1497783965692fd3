#pragma once
// The ASL folder layout of EuRoC MAV and TUM-VI (docs/formats.md "EuRoC / ASL"):
// SEQ/mav0/cam{0,1}/{data.csv, data/<timestamp_ns>.png, sensor.yaml}, ground truth in
// mav0/state_groundtruth_estimate0/data.csv (EuRoC) or mav0/mocap0/data.csv (TUM-VI).
#include <memory>
#include <string>

#include "system/datasets/rig_stereo_source.h"

namespace cslam {

/// The folder holding cam0/ and cam1/ (`path`/mav0 or `path` itself), or "" when neither has them.
std::string AslCameraFolder(const std::string& path);

/// Opens an ASL sequence. The cameras are paired by timestamp (equal to the nanosecond; the
/// frames left without a partner are reported in the log and skipped). `calib` ("" = the two
/// sensor.yaml files) and `gt` (TUM format, "" = the dataset's own ground truth when present)
/// override what the layout holds. Throws InputError naming the file (and line) when a
/// sensor.yaml or data.csv is missing or malformed, or data.csv names a missing image.
std::unique_ptr<RigStereoSource> OpenAslSequence(const std::string& path, const std::string& calib,
                                                 const std::string& gt);

}  // namespace cslam
