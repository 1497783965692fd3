// Fuzz target: a user's rig files over the same bytes: every stereo calibration format
// (Kalibr, OpenCV, ORB-SLAM3, an EuRoC sensor.yaml pair), the rig checks, the rectification of
// a small rig that passes them, and both ground-truth pose formats.
#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/datasets/rig_calibration.h"
#include "system/datasets/stereo_rectifier.h"
#include "system/datasets/timed_poses.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cslam::fuzz::WriteInput(data, size, "rig.yaml");
  const auto rectify = [](const cslam::StereoRig& rig) {
    cslam::CheckStereoRig(rig);
    // Maps cost width × height: keep the fuzzer fast, the checks above bound the rest.
    if (static_cast<long>(rig.cam0.width) * rig.cam0.height <= 64 * 64) cslam::StereoRectifier r(rig);
  };
  try {
    rectify(cslam::ReadRigCalibration(path));
  } catch (const cslam::Error&) {
  }
  try {
    rectify(cslam::ReadEurocSensorPair(path, path));
  } catch (const cslam::Error&) {
  }
  for (auto read : {&cslam::ReadTumPoses, &cslam::ReadAslPoses}) {
    try {
      const cslam::TimedPoses p = read(path);
      cslam::InterpolatePoses(p, {p.times.front(), 0.5 * (p.times.front() + p.times.back())});
    } catch (const cslam::Error&) {
    }
  }
  return 0;
}
