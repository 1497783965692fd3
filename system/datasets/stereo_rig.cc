#include "system/datasets/stereo_rig.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace cslam {

bool CameraIntrinsics::HasDistortion() const {
  for (double k : distortion)
    if (k != 0.0) return true;
  return false;
}

namespace {

std::string Metres(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

void CheckCamera(const StereoRig& rig, const CameraIntrinsics& cam, const std::string& name) {
  if (!(cam.fx > 0) || !(cam.fy > 0) || !std::isfinite(cam.cx) || !std::isfinite(cam.cy))
    throw InputError(rig.source, name + ": expected positive focal lengths and a finite principal point");
  if (cam.width <= 0 || cam.height <= 0 || cam.width > 20000 || cam.height > 20000)
    throw InputError(rig.source, name + ": expected an image size (resolution) of 1-20000 pixels a side, got " +
                                     std::to_string(cam.width) + "x" + std::to_string(cam.height));
  const size_t n = cam.distortion.size();
  if (cam.lens == LensModel::kRadialTangential && n != 4 && n != 5)
    throw InputError(rig.source, name + ": expected 4 or 5 radial-tangential coefficients "
                                        "(k1 k2 p1 p2 [k3]), got " + std::to_string(n));
  if (cam.lens == LensModel::kEquidistant && n != 4)
    throw InputError(rig.source, name + ": expected 4 equidistant coefficients (k1 k2 k3 k4), got " +
                                     std::to_string(n));
  for (double k : cam.distortion)
    if (!std::isfinite(k)) throw InputError(rig.source, name + ": expected finite distortion coefficients");
}

}  // namespace

void CheckStereoRig(const StereoRig& rig) {
  CheckCamera(rig, rig.cam0, "cam0");
  CheckCamera(rig, rig.cam1, "cam1");
  if (rig.cam0.width != rig.cam1.width || rig.cam0.height != rig.cam1.height)
    throw InputError(rig.source, "expected both cameras at the same resolution (the rectified pair shares one), "
                                 "got cam0 " + std::to_string(rig.cam0.width) + "x" + std::to_string(rig.cam0.height) +
                                     ", cam1 " + std::to_string(rig.cam1.width) + "x" + std::to_string(rig.cam1.height));
  if (rig.cam0.lens != rig.cam1.lens)
    throw InputError(rig.source, "mixed distortion models: cam0 is " +
                                     NameOf(kLensModelNames, rig.cam0.lens) + ", cam1 " +
                                     NameOf(kLensModelNames, rig.cam1.lens) +
                                     "; expected the same model for both cameras");
  const Eigen::Vector3d t = rig.cam1_from_cam0.translation();
  const double b = t.norm();
  if (!std::isfinite(b) || b > 2.0)
    throw InputError(rig.source, "the baseline is " + Metres(b) +
                                     " m; expected 0.01-2 m for a stereo rig (millimetres? the "
                                     "translation must be given in metres)");
  if (b < 0.01)
    throw InputError(rig.source, "the baseline is " + Metres(b) +
                                     " m; expected 0.01-2 m for a stereo rig (is the translation "
                                     "in metres, and are cam0 and cam1 two different cameras?)");
  // cam1 sits at +x in cam0, so cam0's centre, seen from cam1 (= the translation), is at -x.
  if (std::abs(t.x()) < 0.8 * b)
    throw InputError(rig.source, "the translation between the cameras (" + Metres(t.x()) + ", " +
                                     Metres(t.y()) + ", " + Metres(t.z()) +
                                     ") m is not mostly along x; expected a side-by-side pair with "
                                     "cam1 to the right of cam0");
  if (t.x() > 0)
    throw InputError(rig.source, "T looks inverted: Kalibr's T_cn_cnm1 maps cam0 to cam1, so its "
                                     "x is negative (-baseline) when cam1 is the right camera; got "
                                     "x = " + Metres(t.x()) + " m (swap the cameras or invert T)");
}

}  // namespace cslam
