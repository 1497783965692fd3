#pragma once
// A rectified stereo camera of KITTI's proportions (1200×360 px, f = 700 px, 0.5 m baseline)
// for tests that need one but not a real calibration.
#include "core/stereo_camera.h"

namespace cslam::testing {

inline StereoCamera KittiSizedCamera() {
  StereoCamera c;
  c.fx = c.fy = 700;
  c.cx = 600;
  c.cy = 180;
  c.baseline = 0.5;
  c.width = 1200;
  c.height = 360;
  return c;
}

}  // namespace cslam::testing
