#pragma once
// Rectified pinhole stereo camera (clusterslam_spec.md §1).
//
// Frames: the camera frame is the LEFT camera's: x right, y down, z forward, metres. A stereo
// keypoint is x = (uL, vL, uR) in pixels; the right camera sits at +baseline along x, so its
// image coordinate is uR = uL - fx * b / Z and disparity d = uL - uR > 0.
#include <Eigen/Core>

namespace cslam {

/// Intrinsics and baseline of a rectified stereo pair. Templated projection so Ceres autodiff
/// can use it; the covariance helpers are double-only.
struct StereoCamera {
  double fx = 0, fy = 0;   ///< focal lengths, px
  double cx = 0, cy = 0;   ///< principal point, px
  double baseline = 0;     ///< metres, > 0
  int width = 0, height = 0;  ///< image size, px

  /// Throws ConfigError naming the field when a value is not usable.
  void Check() const;

  /// Projects a point in the left camera frame to (uL, vL, uR). Returns false when the point
  /// is not in front of the camera (Z <= min_depth); the output is still written when Z != 0.
  template <typename T>
  bool Project(const Eigen::Matrix<T, 3, 1>& p_in_cam, Eigen::Matrix<T, 3, 1>* x,
               double min_depth = 1e-6) const {
    const T& z = p_in_cam.z();
    if (!(z > T(min_depth))) {
      if (z != T(0)) {
        (*x)(0) = T(fx) * p_in_cam.x() / z + T(cx);
        (*x)(1) = T(fy) * p_in_cam.y() / z + T(cy);
        (*x)(2) = (*x)(0) - T(fx * baseline) / z;
      }
      return false;
    }
    (*x)(0) = T(fx) * p_in_cam.x() / z + T(cx);
    (*x)(1) = T(fy) * p_in_cam.y() / z + T(cy);
    (*x)(2) = (*x)(0) - T(fx * baseline) / z;
    return true;
  }

  /// Back-projects (uL, vL, uR) into the left camera frame. Returns false when the disparity
  /// is not positive. When `jacobian` is given it receives d(X,Y,Z)/d(uL,vL,uR).
  template <typename T>
  bool BackProject(const Eigen::Matrix<T, 3, 1>& x, Eigen::Matrix<T, 3, 1>* p_in_cam,
                   Eigen::Matrix<T, 3, 3>* jacobian = nullptr) const {
    const T d = x(0) - x(2);
    if (!(d > T(0))) return false;
    const T b = T(baseline);
    const T r = T(fx / fy);
    (*p_in_cam)(0) = (x(0) - T(cx)) * b / d;
    (*p_in_cam)(1) = (x(1) - T(cy)) * r * b / d;
    (*p_in_cam)(2) = T(fx) * b / d;
    if (jacobian) {
      const T d2 = d * d;
      auto& J = *jacobian;
      J(0, 0) = b * (T(cx) - x(2)) / d2;
      J(0, 1) = T(0);
      J(0, 2) = b * (x(0) - T(cx)) / d2;
      J(1, 0) = -(x(1) - T(cy)) * r * b / d2;
      J(1, 1) = r * b / d;
      J(1, 2) = (x(1) - T(cy)) * r * b / d2;
      J(2, 0) = -T(fx) * b / d2;
      J(2, 1) = T(0);
      J(2, 2) = T(fx) * b / d2;
    }
    return true;
  }

  /// True when (uL, vL) and uR fall inside the image (uR only needs to be inside the width).
  bool InImage(const Eigen::Vector3d& x, double border_px = 0.0) const;

  /// Covariance of the back-projected 3-D point, J Σ Jᵀ (metres²). Precondition: positive
  /// disparity.
  Eigen::Matrix3d PointCovariance(const Eigen::Vector3d& x, const Eigen::Matrix3d& pixel_cov) const;
};

}  // namespace cslam
