#pragma once
// Explicit geometry of a synthetic scene: every rigid body (object 0 = the static world) is a
// list of textured rectangles in the body's own frame; the body's pose per frame lives beside
// it (SyntheticSequence::world_from_object). The landmark generator ray-casts against these
// rectangles and an offscreen renderer can draw them as they are (two triangles each).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// A one-sided textured rectangle. Corners: origin, origin + edge_u, origin + edge_v,
/// origin + edge_u + edge_v (edges orthogonal). The front side faces Normal() = edge_u × edge_v;
/// landmarks on it are only observable from the front, but it blocks rays from both sides.
struct SceneQuad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< a corner, body frame, metres
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();  ///< first edge, metres
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();  ///< second edge, orthogonal to edge_u
  Eigen::Vector3f color = Eigen::Vector3f::Constant(0.5f);  ///< base colour, linear RGB in [0,1]
  int texture = 0;  ///< seed of a procedural texture for renderers (same value = same pattern)

  Eigen::Vector3d Normal() const { return edge_u.cross(edge_v).normalized(); }
  Eigen::Vector3d Center() const { return origin + 0.5 * (edge_u + edge_v); }
  double Area() const { return edge_u.cross(edge_v).norm(); }
  /// The point at rectangle coordinates (a, b) in [0,1]².
  Eigen::Vector3d At(double a, double b) const { return origin + a * edge_u + b * edge_v; }
  /// The same rectangle mapped by `b_from_a` (its points are given in frame a).
  SceneQuad Transformed(const Pose& b_from_a) const;
  bool operator==(const SceneQuad&) const = default;
};

/// One rigid body's surfaces, in the body frame.
struct SceneBody {
  std::string kind;  ///< "static", "car", "box", ... (for renderers and summaries)
  std::vector<SceneQuad> quads;
  bool operator==(const SceneBody&) const = default;
};

/// All bodies of a scene, indexed by object id (0 = the static world, posed at identity).
struct SceneGeometry {
  std::vector<SceneBody> bodies;
  bool operator==(const SceneGeometry&) const = default;
};

/// Appends the six faces of an axis-aligned box of `size` (metres) centred at the origin of
/// frame `box`, mapped into the body frame by `body_from_box`. Faces point outwards, or inwards
/// with `inward` (a room seen from inside). `with_bottom` = false omits the -z face (a box that
/// stands on the ground).
void AddBox(const Pose& body_from_box, const Eigen::Vector3d& size, const Eigen::Vector3f& color,
            int texture, std::vector<SceneQuad>* quads, bool with_bottom = true, bool inward = false);

/// Parameter t in (0, 1) at which the segment from `a` to `b` crosses the quad (both in the
/// quad's frame), or -1 when it does not cross it. Touching the end point b (t = 1) is no hit.
double IntersectSegment(const SceneQuad& quad, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// Brute-force occlusion test: true when some quad of some body, posed at `frame`, crosses the
/// segment from `from` to `to` (world frame) more than `clearance_m` metres before `to`.
/// O(all quads); the generator uses a culled equivalent, tests use this one.
bool SegmentBlocked(const SceneGeometry& geometry,
                    const std::vector<std::vector<Pose>>& world_from_object, int frame,
                    const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                    double clearance_m = 1e-6);

}  // namespace cslam
