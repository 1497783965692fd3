#pragma once
// The virtual camera of a rendered picture, in the project's camera convention (x right,
// y down, z forward; pixel (0,0) is the centre of the top-left pixel). Renderers build the GL
// matrices from it, and tests use Project() to know where a point must appear.
#include <Eigen/Core>

#include "core/rigid.h"

namespace cslam {

/// A pinhole virtual camera producing a width x height image.
struct RenderView {
  Pose view_from_world = Pose::Identity();
  double fx = 500, fy = 500;  ///< px
  double cx = 320, cy = 240;  ///< px
  int width = 640, height = 480;  ///< px
  double near_m = 0.1, far_m = 1000.0;  ///< depth clipping planes, metres

  /// Pixel of a world point; false when it is not between the clipping planes.
  bool Project(const Eigen::Vector3d& p_world, Eigen::Vector2d* pixel) const;

  /// The same view rendered `factor` times larger in each direction (supersampling): a point
  /// at pixel u here lands at factor * (u + 0.5) - 0.5 there.
  RenderView Scaled(int factor) const;

  /// Column-major-ready OpenGL projection matrix (clip from GL eye coordinates) such that
  /// after reading the buffer back top row first, Project() gives the pixel.
  Eigen::Matrix4d GlProjection() const;
  /// OpenGL modelview matrix: GL eye (x right, y up, z backward) from world.
  Eigen::Matrix4d GlModelView() const;
};

/// view_from_world of a camera at `eye` looking at `target`, with image "up" as close to
/// `up_world` as possible. Precondition: eye != target and up_world not parallel to the view
/// direction.
Pose LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
            const Eigen::Vector3d& up_world);

}  // namespace cslam
