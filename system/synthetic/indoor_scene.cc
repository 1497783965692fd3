#include <algorithm>
#include <cmath>

#include "core/logging.h"
#include "system/synthetic/scene_draft.h"

namespace cslam::synthetic_detail {

namespace {

/// Room [-W/2, W/2] × [-D/2, D/2] × [0, H], seen from inside.
struct Room {
  double W = 0, D = 0, H = 0;
};

// Shelves, cabinets, sofas, tables and pictures along one wall.
void FurnishWall(const Room& room, int wall, Rng& scene, SceneBody* body) {
  auto add_box = [&](const Pose& g_from_item, const Eigen::Vector3d& centre,
                     const Eigen::Vector3d& size, const Eigen::Vector3f& color) {
    AddBox(g_from_item * MakePose(Eigen::Matrix3d::Identity(), centre), size, color,
           scene.Texture(), &body->quads, false);
  };
  // Wall frame: x along the wall, y into the room, z up; origin at the wall's left end.
  const double len = wall % 2 == 0 ? room.W : room.D;
  const double half_other = wall % 2 == 0 ? 0.5 * room.D : 0.5 * room.W;
  const double angle = wall * 0.5 * kPi;
  const Pose g_from_wall = MakePose(Rz(angle), Rz(angle) * Eigen::Vector3d(-0.5 * len, -half_other, 0));
  for (double a = scene.Uniform(0.2, 0.8); a < len - 0.5;) {
    const int kind = scene.Int(0, 3);
    const double w = kind == 2 ? scene.Uniform(1.6, 2.2) : scene.Uniform(0.6, 1.6);
    if (a + w > len - 0.2) break;
    const Pose g_from_item = g_from_wall * MakePose(Eigen::Matrix3d::Identity(), {a + 0.5 * w, 0, 0});
    const Eigen::Vector3f color = scene.Color(0.2f, 0.8f);
    if (kind == 0) {  // shelf with boxes on it
      const double depth = scene.Uniform(0.3, 0.45), h = scene.Uniform(1.6, 2.2);
      add_box(g_from_item, {0, 0.5 * depth + 0.01, 0.5 * h}, {w, depth, h}, color);
    } else if (kind == 1) {  // cabinet with small items on top
      const double depth = scene.Uniform(0.45, 0.6), h = scene.Uniform(0.7, 1.0);
      add_box(g_from_item, {0, 0.5 * depth + 0.01, 0.5 * h}, {w, depth, h}, color);
      for (int i = scene.Int(0, 3); i > 0; --i) {
        const double sz = scene.Uniform(0.05, 0.35), sy = scene.Uniform(0.1, 0.3),
                     sx = scene.Uniform(0.1, 0.3);
        const Eigen::Vector3d s(sx, sy, sz);
        const Eigen::Vector3f color = scene.Color(0.1f, 0.95f);
        add_box(g_from_item, {scene.Uniform(-0.35, 0.35) * w, 0.5 * depth, h + 0.5 * s.z()}, s, color);
      }
    } else if (kind == 2) {  // sofa: seat and back
      const double depth = scene.Uniform(0.75, 0.9);
      add_box(g_from_item, {0, 0.5 * depth + 0.01, 0.22}, {w, depth, 0.44}, color);
      add_box(g_from_item, {0, 0.11, 0.62}, {w, 0.2, 0.36}, color);
    } else {  // table with legs
      const double depth = scene.Uniform(0.6, 0.8), h = scene.Uniform(0.72, 0.76);
      add_box(g_from_item, {0, 0.5 * depth + 0.01, h - 0.025}, {w, depth, 0.05}, color);
      for (double sx : {-1.0, 1.0})
        for (double sy : {0.06, depth - 0.04})
          add_box(g_from_item, {sx * (0.5 * w - 0.05), sy, 0.5 * (h - 0.05)}, {0.05, 0.05, h - 0.05},
                  color);
    }
    a += w + scene.Uniform(0.2, 1.0);
  }
  for (int i = scene.Int(0, 2); i > 0; --i) {  // pictures
    const double sz = scene.Uniform(0.3, 0.7), sx = scene.Uniform(0.4, 1.0);
    const Eigen::Vector3d s(sx, 0.02, sz);
    const Eigen::Vector3f color = scene.Color(0.05f, 1.0f);
    add_box(g_from_wall, {scene.Uniform(0.2, 0.8) * len, 0.011, scene.Uniform(1.5, 2.0)}, s, color);
  }
}

// The static world: the room's shell and its furniture.
SceneBody FurnishRoom(const Room& r, Rng& scene) {
  SceneBody room;
  room.kind = "static";
  std::vector<SceneQuad> shell;
  const int texture = scene.Texture();
  const Eigen::Vector3f color = scene.Color(0.5f, 0.9f);
  AddBox(MakePose(Eigen::Matrix3d::Identity(), {0, 0, 0.5 * r.H}), {r.W, r.D, r.H}, color, texture,
         &shell, true, true);
  for (auto& q : shell) {
    q.color = scene.Color(0.4f, 0.9f);
    q.texture = scene.Texture();
    AddTiled(q, 2.0, &room.quads);
  }
  for (int wall = 0; wall < 4; ++wall) FurnishWall(r, wall, scene, &room);
  return room;
}

/// Where the hand-held camera is at each frame, and the depth (y) of its walk.
struct CameraWalk {
  std::vector<Eigen::Vector3d> pos;
  double y = 0;
};

// Camera: hand-held, walking to and fro along the near side of the room (0.3–2.1 m/s mean
// speed), looking into the far half where the objects move, with small smooth wobbles.
CameraWalk WalkCamera(const Room& room, const std::vector<double>& t, Rng& traj, Draft* d) {
  const int frames = static_cast<int>(t.size());
  const double span = traj.Uniform(0.5, 1.0) * (0.5 * room.W - 1.3);
  const double v_cam = traj.Uniform(0.3, 2.1);
  const double omega_cam = std::min(2.0, v_cam * kPi / (2 * span)), phase_cam = traj.Uniform(0, 2 * kPi);
  CameraWalk walk;
  walk.y = -0.5 * room.D + traj.Uniform(1.2, 1.4);
  const double h0 = traj.Uniform(1.3, 1.7);
  Eigen::Matrix<double, 8, 2> wob;  // (omega, phase) of the wobbles
  for (int i = 0; i < 8; ++i) wob.row(i) << 2 * kPi / traj.Uniform(1.5, 8), traj.Uniform(0, 2 * kPi);
  auto wobble = [&](int i, double time) { return std::sin(wob(i, 0) * time + wob(i, 1)); };
  walk.pos.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Vector3d pos(span * std::sin(omega_cam * t[f] + phase_cam), walk.y + 0.2 * wobble(5, t[f]),
                              h0 + 0.06 * wobble(0, t[f]));
    const Eigen::Vector3d target(0.3 * pos.x() + 0.6 * wobble(1, t[f]), 0.25 * room.D + 0.5 * wobble(2, t[f]),
                                 0.7 + 0.2 * wobble(3, t[f]));
    walk.pos[f] = pos;
    d->g_from_cam.push_back(CameraPose(pos, target - pos, 0.03 * wobble(4, t[f])));
  }
  return walk;
}

// One or two stacked boxes; `radius` receives the radius of a sphere around them.
SceneBody MakeMovingBox(Rng& scene, double* radius) {
  SceneBody body;
  body.kind = "box";
  const double size_z = scene.Uniform(0.2, 0.6), size_y = scene.Uniform(0.2, 0.6),
               size_x = scene.Uniform(0.2, 0.6);
  const Eigen::Vector3d size(size_x, size_y, size_z);
  {
    const int texture = scene.Texture();
    const Eigen::Vector3f color = scene.Color(0.1f, 1.0f);
    AddBox(Pose::Identity(), size, color, texture, &body.quads);
  }
  *radius = 0.5 * size.norm();
  if (scene.Chance(0.5)) {
    const double top_z = scene.Uniform(0.1, 0.3), top_y = scene.Uniform(0.1, 1.0) * size.y(),
                 top_x = scene.Uniform(0.1, 1.0) * size.x();
    const Eigen::Vector3d top(top_x, top_y, top_z);
    const int texture = scene.Texture();
    const Eigen::Vector3f color = scene.Color(0.1f, 1.0f);
    AddBox(MakePose(Eigen::Matrix3d::Identity(), {0, 0, 0.5 * (size.z() + top.z())}), top, color,
           texture, &body.quads, false);
    *radius = std::max(*radius, (Eigen::Vector3d(0.5 * size.x(), 0.5 * size.y(), 0.5 * size.z() + top.z())).norm());
  }
  return body;
}

/// The objects placed so far: each one's centre per frame and its radius.
using Placed = std::vector<std::pair<std::vector<Eigen::Vector3d>, double>>;

/// A moving object's poses and centres per frame.
struct BoxPlan {
  std::vector<Pose> poses;
  std::vector<Eigen::Vector3d> centre;
  int visible = -1;  ///< frames in view; -1: no plan kept clear of everything
};

// Drifting smoothly (0.1–1 m/s) and turning; each plan is redrawn until the object keeps
// clear of the walls, the camera and the other objects and stays in view for `min_visible`
// frames. The plan in view longest is kept; without any, the last one drawn.
BoxPlan PlanBox(const Room& room, const CameraWalk& walk, const std::vector<double>& t,
                double radius, const Placed& accepted, const StereoCamera& cam, const Draft& d,
                int min_visible, Rng& traj) {
  const int frames = static_cast<int>(t.size());
  std::vector<Pose> poses(frames);
  std::vector<Eigen::Vector3d> centre(frames);
  BoxPlan best;
  for (int attempt = 0; attempt < 1000 && best.visible < min_visible; ++attempt) {
    const double speed = traj.Uniform(0.1, 1.0);
    Eigen::Matrix<double, 3, 2> amp, omega, phase;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) {
        omega(i, j) = 2 * kPi / traj.Uniform(1.5, 5);
        phase(i, j) = traj.Uniform(0, 2 * kPi);
        amp(i, j) = (i == 2 ? 0.25 : 0.7) * speed / omega(i, j) * traj.Uniform(0.3, 1.0);
      }
    // Start high enough that the vertical sway never reaches the floor.
    const double sway = 2 * amp.row(2).sum();
    const double z_lo = radius + 0.05 + sway, z_hi = std::min(1.5, room.H - 0.3 - radius - sway);
    const double c0_z = z_hi > z_lo ? traj.Uniform(z_lo, z_hi) : z_lo;
    const double c0_y = traj.Uniform(walk.y + 0.9, 0.5 * room.D - 1.0);
    const double c0_x = traj.Uniform(-0.5, 0.5) * (room.W - 2.4);
    const Eigen::Vector3d c0(c0_x, c0_y, c0_z);
    const double yaw0 = traj.Uniform(0, 2 * kPi), yaw_rate = traj.Sign() * traj.Uniform(0.2, 1.0);
    const double tilt = traj.Uniform(0.05, 0.25), tilt_w = 2 * kPi / traj.Uniform(2, 6),
                 tilt_phase = traj.Uniform(0, 2 * kPi);
    int visible = 0;
    bool ok = true;
    for (int f = 0; f < frames && ok; ++f) {
      Eigen::Vector3d c = c0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 2; ++j)
          c[i] += amp(i, j) * (std::sin(omega(i, j) * t[f] + phase(i, j)) - std::sin(phase(i, j)));
      centre[f] = c;
      const double tilt_now = tilt * std::sin(tilt_w * t[f] + tilt_phase);
      poses[f] = MakePose(Rz(yaw0 + yaw_rate * t[f]) * Ry(tilt_now) * Rx(0.5 * tilt_now), c);
      if (std::abs(c.x()) > 0.5 * room.W - 1.0 - radius || c.y() > 0.5 * room.D - 1.0 - radius ||
          c.y() < walk.y + 0.6 + radius ||
          c.z() < radius + 0.02 || c.z() > room.H - 0.3 - radius)
        ok = false;
      if ((c - walk.pos[f]).norm() < radius + 0.5) ok = false;
      for (const auto& [other, other_radius] : accepted)
        if ((c - other[f]).norm() < radius + other_radius + 0.05) ok = false;
      if (InFrustum(d.g_from_cam[f], cam, c, 0.5, 7.0)) ++visible;
    }
    if (ok && visible > best.visible) {
      best.visible = visible;
      best.poses = poses;
      best.centre = centre;
    }
  }
  if (best.visible < 0) {
    best.poses = poses;
    best.centre = centre;
  }
  return best;
}

}  // namespace

Draft BuildIndoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj) {
  DraftStart start = StartDraft(kIndoor, options, scene);
  Draft& d = start.draft;
  const std::vector<double>& t = start.t;
  const int frames = static_cast<int>(t.size());

  Room room;
  room.W = scene.Uniform(6, 10);
  room.D = scene.Uniform(6, 9);
  room.H = scene.Uniform(2.6, 3.2);
  d.geometry.bodies.push_back(FurnishRoom(room, scene));
  d.g_from_object.push_back(std::vector<Pose>(frames, Pose::Identity()));
  const CameraWalk walk = WalkCamera(room, t, traj, &d);

  const int num_objects = start.objects;
  const int min_visible = static_cast<int>(0.6 * frames);
  Placed accepted;
  for (int k = 0; k < num_objects; ++k) {
    double radius = 0;
    SceneBody body = MakeMovingBox(scene, &radius);
    BoxPlan plan = PlanBox(room, walk, t, radius, accepted, cam, d, min_visible, traj);
    if (plan.visible < min_visible)
      GetLogger("system")->warn("synthetic: object {} is in view in only {} frames", k + 1,
                                std::max(plan.visible, 0));
    accepted.emplace_back(plan.centre, radius);
    d.geometry.bodies.push_back(std::move(body));
    d.g_from_object.push_back(std::move(plan.poses));
  }
  return std::move(d);
}

}  // namespace cslam::synthetic_detail
