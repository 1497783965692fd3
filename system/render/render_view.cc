#include "system/render/render_view.h"

#include <Eigen/Geometry>

namespace cslam {

bool RenderView::Project(const Eigen::Vector3d& p_world, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d p = view_from_world * p_world;
  if (p.z() < near_m || p.z() > far_m) return false;
  *pixel = Eigen::Vector2d(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
  return true;
}

RenderView RenderView::Scaled(int factor) const {
  RenderView s = *this;
  s.fx = fx * factor;
  s.fy = fy * factor;
  s.cx = factor * (cx + 0.5) - 0.5;
  s.cy = factor * (cy + 0.5) - 0.5;
  s.width = width * factor;
  s.height = height * factor;
  return s;
}

Eigen::Matrix4d RenderView::GlProjection() const {
  // Pixel centre u sits at GL window x = u + 0.5; the buffer is flipped on read-back, so
  // image row v sits at window y = height - (v + 0.5).
  const double w = width, h = height, n = near_m, f = far_m;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2.0 * fx / w;
  m(0, 2) = 1.0 - 2.0 * (cx + 0.5) / w;
  m(1, 1) = 2.0 * fy / h;
  m(1, 2) = 2.0 * (cy + 0.5) / h - 1.0;
  m(2, 2) = -(f + n) / (f - n);
  m(2, 3) = -2.0 * f * n / (f - n);
  m(3, 2) = -1.0;
  return m;
}

Eigen::Matrix4d RenderView::GlModelView() const {
  Eigen::Matrix4d gl_from_view = Eigen::Matrix4d::Identity();
  gl_from_view(1, 1) = -1.0;
  gl_from_view(2, 2) = -1.0;
  return gl_from_view * view_from_world.matrix();
}

Pose LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
            const Eigen::Vector3d& up_world) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = (-up_world).cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_view_rotation;
  world_from_view_rotation << x, y, z;
  Pose view_from_world = Pose::Identity();
  view_from_world.linear() = world_from_view_rotation.transpose();
  view_from_world.translation() = -(world_from_view_rotation.transpose() * eye);
  return view_from_world;
}

}  // namespace cslam
