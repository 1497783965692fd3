#include "core/stereo_camera.h"

#include <cmath>
#include <string>

#include "core/errors.h"

namespace cslam {

void StereoCamera::Check() const {
  auto bad = [](const std::string& what) { throw ConfigError("camera: " + what); };
  if (!(std::isfinite(fx) && fx > 0)) bad("fx must be a positive number, got " + std::to_string(fx));
  if (!(std::isfinite(fy) && fy > 0)) bad("fy must be a positive number, got " + std::to_string(fy));
  if (!std::isfinite(cx) || !std::isfinite(cy)) bad("cx and cy must be finite");
  if (!(std::isfinite(baseline) && baseline > 0))
    bad("baseline must be a positive number of metres, got " + std::to_string(baseline));
  if (width <= 0 || height <= 0)
    bad("width and height must be positive, got " + std::to_string(width) + "x" +
        std::to_string(height));
}

bool StereoCamera::InImage(const Eigen::Vector3d& x, double border_px) const {
  return x(0) >= border_px && x(0) <= width - 1 - border_px && x(1) >= border_px &&
         x(1) <= height - 1 - border_px && x(2) >= border_px && x(2) <= width - 1 - border_px;
}

Eigen::Matrix3d StereoCamera::PointCovariance(const Eigen::Vector3d& x,
                                              const Eigen::Matrix3d& pixel_cov) const {
  Eigen::Vector3d p;
  Eigen::Matrix3d J;
  const bool ok = BackProject<double>(x, &p, &J);
  CSLAM_CHECK(ok, "PointCovariance needs a positive disparity");
  return J * pixel_cov * J.transpose();
}

}  // namespace cslam
