#include "system/synthetic/scene_geometry.h"

#include <cmath>

namespace cslam {

SceneQuad SceneQuad::Transformed(const Pose& b_from_a) const {
  SceneQuad q = *this;
  q.origin = b_from_a * origin;
  q.edge_u = b_from_a.linear() * edge_u;
  q.edge_v = b_from_a.linear() * edge_v;
  return q;
}

void AddBox(const Pose& body_from_box, const Eigen::Vector3d& size, const Eigen::Vector3f& color,
            int texture, std::vector<SceneQuad>* quads, bool with_bottom, bool inward) {
  const Eigen::Vector3d h = 0.5 * size;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    for (int sign : {+1, -1}) {
      if (i == 2 && sign < 0 && !with_bottom) continue;
      Eigen::Vector3d origin = Eigen::Vector3d::Zero();
      origin[i] = sign * h[i];
      origin[j] = -h[j];
      origin[k] = -h[k];
      Eigen::Vector3d ej = Eigen::Vector3d::Zero(), ek = Eigen::Vector3d::Zero();
      ej[j] = size[j];
      ek[k] = size[k];
      // e_j × e_k = e_i: the order of the edges sets which way the face points.
      const bool outward_order = (sign > 0) != inward;
      SceneQuad q;
      q.origin = origin;
      q.edge_u = outward_order ? ej : ek;
      q.edge_v = outward_order ? ek : ej;
      q.color = color;
      q.texture = texture;
      quads->push_back(q.Transformed(body_from_box));
    }
  }
}

double IntersectSegment(const SceneQuad& quad, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d n = quad.edge_u.cross(quad.edge_v);
  const Eigen::Vector3d d = b - a;
  const double denom = n.dot(d);
  if (std::abs(denom) < 1e-15 * n.norm() * d.norm()) return -1.0;  // parallel
  const double t = n.dot(quad.origin - a) / denom;
  if (!(t > 0.0 && t < 1.0)) return -1.0;
  const Eigen::Vector3d x = a + t * d - quad.origin;
  const double s = x.dot(quad.edge_u) / quad.edge_u.squaredNorm();
  const double r = x.dot(quad.edge_v) / quad.edge_v.squaredNorm();
  if (s < 0.0 || s > 1.0 || r < 0.0 || r > 1.0) return -1.0;
  return t;
}

bool SegmentBlocked(const SceneGeometry& geometry,
                    const std::vector<std::vector<Pose>>& world_from_object, int frame,
                    const Eigen::Vector3d& from, const Eigen::Vector3d& to, double clearance_m) {
  const double length = (to - from).norm();
  if (length <= clearance_m) return false;
  const double t_max = 1.0 - clearance_m / length;
  for (size_t o = 0; o < geometry.bodies.size(); ++o) {
    const Pose object_from_world = world_from_object[o][frame].inverse();
    const Eigen::Vector3d a = object_from_world * from, b = object_from_world * to;
    for (const SceneQuad& q : geometry.bodies[o].quads) {
      const double t = IntersectSegment(q, a, b);
      if (t > 0.0 && t < t_max) return true;
    }
  }
  return false;
}

}  // namespace cslam
