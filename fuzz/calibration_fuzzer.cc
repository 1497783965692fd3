// Fuzz target: the KITTI calibration readers (calib.txt, calib_cam_to_cam.txt, the rigid
// calib_*_to_*.txt files) over the same bytes.
#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/datasets/kitti_calibration.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cslam::fuzz::WriteInput(data, size, "calib.txt");
  try {
    cslam::ReadKittiOdometryCalibration(path);
  } catch (const cslam::Error&) {
  }
  try {
    const cslam::KittiCamToCam c = cslam::ReadKittiCamToCam(path);
    for (int left : {0, 2}) {
      try {
        cslam::StereoCameraFromCamToCam(c, left, left + 1);
        cslam::CamFromCam0Rect(c, left);
      } catch (const cslam::Error&) {
      }
    }
  } catch (const cslam::Error&) {
  }
  try {
    cslam::ReadKittiRigidCalibration(path);
  } catch (const cslam::Error&) {
  }
  return 0;
}
