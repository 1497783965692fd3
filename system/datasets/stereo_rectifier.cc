#include "system/datasets/stereo_rectifier.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/errors.h"
#include "core/logging.h"
#include "core/options_reader.h"

namespace cslam {

namespace {

cv::Mat CameraMatrix(const CameraIntrinsics& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

cv::Mat Distortion(const CameraIntrinsics& c) {
  if (c.lens == LensModel::kNone) return cv::Mat::zeros(1, 4, CV_64F);
  return cv::Mat(c.distortion, true).reshape(1, 1);
}

bool AlreadyRectified(const StereoRig& rig) {
  const CameraIntrinsics &a = rig.cam0, &b = rig.cam1;
  const Eigen::Vector3d t = rig.cam1_from_cam0.translation();
  return !a.HasDistortion() && !b.HasDistortion() && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
         a.cy == b.cy && rig.cam1_from_cam0.linear().isIdentity(1e-12) && t.y() == 0 && t.z() == 0;
}

// Whether every pixel of the map samples inside the raw image, with the neighbour bilinear
// interpolation needs.
bool MapsInside(const cv::Mat& mx, const cv::Mat& my, int width, int height) {
  double lo_x, hi_x, lo_y, hi_y;
  cv::minMaxLoc(mx, &lo_x, &hi_x);
  cv::minMaxLoc(my, &lo_y, &hi_y);
  return lo_x >= 0 && lo_y >= 0 && hi_x <= width - 1 && hi_y <= height - 1;
}

void BuildMap(const CameraIntrinsics& c, const cv::Mat& r, const cv::Mat& p, cv::Mat* mx, cv::Mat* my) {
  const cv::Size size(c.width, c.height);
  if (c.lens == LensModel::kEquidistant)
    cv::fisheye::initUndistortRectifyMap(CameraMatrix(c), Distortion(c), r, p, size, CV_32FC1, *mx, *my);
  else
    cv::initUndistortRectifyMap(CameraMatrix(c), Distortion(c), r, p, size, CV_32FC1, *mx, *my);
}

}  // namespace

void RectificationOptions::Check() const {
  CheckOption(zoom_step > 0 && zoom_step <= 0.1, "zoom_step", "must be in (0, 0.1]", zoom_step);
}

StereoRectifier::StereoRectifier(const StereoRig& rig, const RectificationOptions& options) {
  options.Check();
  try {
    Build(rig, options);
  } catch (const cv::Exception& e) {
    // OpenCV's asserts on degenerate intrinsics or distortion: the rig is at fault, not us.
    throw InputError(rig.source, std::string("OpenCV cannot rectify this rig (check the intrinsics and "
                                             "distortion coefficients): ") + e.what());
  } catch (const ConfigError& e) {
    throw InputError(rig.source, std::string("the rectified camera is not usable: ") + e.what());
  }
}

void StereoRectifier::Build(const StereoRig& rig, const RectificationOptions& options) {
  camera_.width = rig.cam0.width;
  camera_.height = rig.cam0.height;
  if (AlreadyRectified(rig) && !rig.given_rectification) {
    identity_ = true;
    camera_.fx = rig.cam0.fx;
    camera_.fy = rig.cam0.fy;
    camera_.cx = rig.cam0.cx;
    camera_.cy = rig.cam0.cy;
    camera_.baseline = -rig.cam1_from_cam0.translation().x();
    camera_.Check();
    return;
  }
  const cv::Size size(rig.cam0.width, rig.cam0.height);
  cv::Mat r0, r1, p0, p1;
  if (rig.given_rectification) {
    cv::eigen2cv(rig.given_rectification->r0, r0);
    cv::eigen2cv(rig.given_rectification->r1, r1);
    cv::eigen2cv(rig.given_rectification->p0, p0);
    cv::eigen2cv(rig.given_rectification->p1, p1);
  } else {
    cv::Mat rot, t, q;
    cv::eigen2cv(Eigen::Matrix3d(rig.cam1_from_cam0.linear()), rot);
    cv::eigen2cv(Eigen::Vector3d(rig.cam1_from_cam0.translation()), t);
    if (rig.cam0.lens == LensModel::kEquidistant)
      cv::fisheye::stereoRectify(CameraMatrix(rig.cam0), Distortion(rig.cam0), CameraMatrix(rig.cam1),
                                 Distortion(rig.cam1), size, rot, t, r0, r1, p0, p1, q,
                                 cv::CALIB_ZERO_DISPARITY, size, /*balance=*/0.0);
    else
      cv::stereoRectify(CameraMatrix(rig.cam0), Distortion(rig.cam0), CameraMatrix(rig.cam1),
                        Distortion(rig.cam1), size, rot, t, r0, r1, p0, p1, q,
                        cv::CALIB_ZERO_DISPARITY, /*alpha=*/0.0, size);
  }
  // A rectified pixel sampled outside the raw image would be black: features on that edge
  // are not in the scene. Zoom in (about the principal point) until none is left.
  int zoom_steps = 0;
  for (;; ++zoom_steps) {
    BuildMap(rig.cam0, r0, p0, &map0x_, &map0y_);
    BuildMap(rig.cam1, r1, p1, &map1x_, &map1y_);
    if (!options.exclude_invalid_pixels || (MapsInside(map0x_, map0y_, size.width, size.height) &&
                                            MapsInside(map1x_, map1y_, size.width, size.height)))
      break;
    if (zoom_steps * options.zoom_step > 1.0)
      throw InputError(rig.source, "cannot rectify this rig without pixels from outside the images "
                                   "(are the intrinsics and the image size right?)");
    for (cv::Mat* p : {&p0, &p1}) {
      p->at<double>(0, 0) *= 1 + options.zoom_step;
      p->at<double>(1, 1) *= 1 + options.zoom_step;
      p->at<double>(0, 3) *= 1 + options.zoom_step;
    }
  }
  // Fixed-point maps remap about twice as fast as float ones; bilinear remap quantises a float
  // map to 1/32 px all the same (INTER_TAB_SIZE), so the output is unchanged.
  cv::convertMaps(cv::Mat(map0x_), cv::Mat(map0y_), map0x_, map0y_, CV_16SC2);
  cv::convertMaps(cv::Mat(map1x_), cv::Mat(map1y_), map1x_, map1y_, CV_16SC2);
  cv::cv2eigen(r0, rect0_from_cam0_);
  cv::cv2eigen(r1, rect1_from_cam1_);
  camera_.fx = p0.at<double>(0, 0);
  camera_.fy = p0.at<double>(1, 1);
  camera_.cx = p0.at<double>(0, 2);
  camera_.cy = p0.at<double>(1, 2);
  camera_.baseline = -p1.at<double>(0, 3) / p1.at<double>(0, 0);
  if (std::abs(p1.at<double>(0, 2) - camera_.cx) > 1e-6 || std::abs(p1.at<double>(1, 2) - camera_.cy) > 1e-6 ||
      std::abs(p1.at<double>(0, 0) - camera_.fx) > 1e-6)
    throw InputError(rig.source, "the given rectification (P1, P2) does not share one focal length and "
                                 "principal point; expected a zero-disparity rectification");
  if (!(camera_.baseline > 0))
    throw InputError(rig.source, "the rectified baseline is not positive; T looks inverted: Kalibr's "
                                 "T_cn_cnm1 maps cam0 to cam1");
  camera_.Check();
  GetLogger("system")->info("rectified {} rig ({}): fx {:.2f} px, cx {:.2f}, cy {:.2f}, baseline {:.4f} m, "
                            "zoomed {:.1f} % to leave no invalid pixel",
                            rig.format, NameOf(kLensModelNames, rig.cam0.lens), camera_.fx, camera_.cx,
                            camera_.cy, camera_.baseline, 100 * (std::pow(1 + options.zoom_step, zoom_steps) - 1));
}

void StereoRectifier::Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_out,
                              cv::Mat* right_out) const {
  if (identity_) {
    *left_out = left;
    *right_out = right;
    return;
  }
  cv::remap(left, *left_out, map0x_, map0y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(right, *right_out, map1x_, map1y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
}

std::string StereoRectifier::RectifiedYamlText() const {
  std::ostringstream s;
  s << std::setprecision(12);
  s << "# The rectified pinhole stereo camera cslam ran on. Trajectories are of the rectified\n"
       "# left camera: rect0 = rect0_from_cam0 * cam0 (docs/formats.md).\n";
  s << "fx: " << camera_.fx << "\nfy: " << camera_.fy << "\ncx: " << camera_.cx << "\ncy: " << camera_.cy
    << "\nbaseline: " << camera_.baseline << "\nwidth: " << camera_.width << "\nheight: " << camera_.height
    << "\n";
  const auto rotation = [&](const char* name, const Eigen::Matrix3d& r) {
    s << name << ":\n";
    for (int i = 0; i < 3; ++i) s << "  - [" << r(i, 0) << ", " << r(i, 1) << ", " << r(i, 2) << "]\n";
  };
  rotation("rect0_from_cam0", rect0_from_cam0_);
  rotation("rect1_from_cam1", rect1_from_cam1_);
  return s.str();
}

}  // namespace cslam
