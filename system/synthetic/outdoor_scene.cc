#include <algorithm>
#include <array>
#include <cmath>

#include "core/logging.h"
#include "system/synthetic/scene_draft.h"

namespace cslam::synthetic_detail {

namespace {

// Half-widths across the main street (y) and along the cross street, metres.
constexpr double kRoad = 9.5, kWalk = 12.5, kYard = 40.0, kCross = 150.0;

/// The camera car: its ground-plane track per frame and its speed.
struct CameraRun {
  std::vector<Eigen::Vector2d> xy;
  SpeedProfile speed;
  /// When the camera passes x (extrapolated at its mean speed between frames).
  double TimeAt(double x, const std::vector<double>& t) const {
    int f = 0;
    const int frames = static_cast<int>(xy.size());
    while (f + 1 < frames && xy[f].x() < x) ++f;
    return t[f] - (xy[f].x() - x) / speed.v;
  }
};

// Camera: a car-mounted rig 1.6 m above the road, inner lane, 5–12 m/s, chosen so a full-length
// sequence travels 120–480 m like the paper's.
CameraRun DriveCamera(const std::vector<double>& t, Rng& traj, Draft* d) {
  const int frames = static_cast<int>(t.size());
  const double duration = t.back();
  double v_lo = std::max(5.0, 120.0 / duration), v_hi = std::min(12.0, 480.0 / duration);
  if (v_lo > v_hi) v_lo = 5.0, v_hi = 12.0;
  CameraRun run;
  const double v_cam = traj.Uniform(v_lo, v_hi);
  run.speed = SpeedProfile{v_cam, 2 * kPi / traj.Uniform(8, 15), traj.Uniform(0, 2 * kPi)};
  const SpeedProfile& cam_speed = run.speed;
  const double lat_amp = traj.Uniform(0.05, 0.2), lat_w = 2 * kPi / traj.Uniform(6, 12),
               lat_phase = traj.Uniform(0, 2 * kPi);
  const double bob_phase = traj.Uniform(0, 2 * kPi), pitch0 = traj.Uniform(-0.03, 0.0);
  run.xy.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const double x = cam_speed.Distance(t[f], 0.0);
    const double y = -1.75 + lat_amp * std::sin(lat_w * t[f] + lat_phase);
    const double dx = cam_speed.v * (1 + 0.1 * std::sin(cam_speed.omega * t[f] + cam_speed.phase));
    const double dy = lat_amp * lat_w * std::cos(lat_w * t[f] + lat_phase);
    const double heading = std::atan2(dy, dx);
    const double pitch = pitch0 + 0.004 * std::sin(2 * kPi * 1.1 * t[f] + bob_phase);
    const Eigen::Vector3d forward(std::cos(heading) * std::cos(pitch),
                                  std::sin(heading) * std::cos(pitch), std::sin(pitch));
    const double z = 1.6 + 0.01 * std::sin(2 * kPi * 1.7 * t[f] + bob_phase);
    run.xy[f] = {x, y};
    d->g_from_cam.push_back(CameraPose({x, y, z}, forward, 0.003 * std::sin(2 * kPi * 0.9 * t[f])));
  }
  return run;
}

/// The main street along x from x_min to x_max, crossed at x_j.
struct Street {
  double x_j = 0, x_min = 0, x_max = 0;
  bool NearJunction(double a, double b, double margin) const {
    return b > x_j - kWalk - margin && a < x_j + kWalk + margin;
  }
};

// Road, sidewalks and yards of both streets.
void AddGround(const Street& st, Rng& scene, SceneBody* world) {
  const Eigen::Vector3f asphalt(0.3f, 0.3f, 0.32f), pavement(0.62f, 0.6f, 0.57f),
      grass(0.3f, 0.45f, 0.2f);
  const double x_j = st.x_j;
  AddTiled(GroundQuad(st.x_min, st.x_max, -kRoad, kRoad, 0, asphalt, scene.Texture()), 20.0,
           &world->quads);
  for (auto [a, b] : {std::pair{st.x_min, x_j - kWalk}, std::pair{x_j + kWalk, st.x_max}}) {
    if (b <= a) continue;
    for (double s : {-1.0, 1.0}) {
      const double y_in = s * kRoad, y_walk = s * kWalk, y_yard = s * kYard;
      AddTiled(GroundQuad(a, b, std::min(y_in, y_walk), std::max(y_in, y_walk), 0, pavement,
                          scene.Texture()), 20.0, &world->quads);
      AddTiled(GroundQuad(a, b, std::min(y_walk, y_yard), std::max(y_walk, y_yard), 0, grass,
                          scene.Texture()), 20.0, &world->quads);
    }
  }
  for (double s : {-1.0, 1.0}) {
    const double y0 = std::min(s * kRoad, s * kCross), y1 = std::max(s * kRoad, s * kCross);
    AddTiled(GroundQuad(x_j - kRoad, x_j + kRoad, y0, y1, 0, asphalt, scene.Texture()), 20.0,
             &world->quads);
    AddTiled(GroundQuad(x_j - kWalk, x_j - kRoad, y0, y1, 0, pavement, scene.Texture()), 20.0,
             &world->quads);
    AddTiled(GroundQuad(x_j + kRoad, x_j + kWalk, y0, y1, 0, pavement, scene.Texture()), 20.0,
             &world->quads);
  }
}

// One side of the main street: buildings, poles and parked cars (parked cars are static:
// label 0).
void AddStreetSide(const Street& st, double side, Rng& scene, SceneBody* world) {
  for (double x = st.x_min; x < st.x_max;) {
    const double w = scene.Uniform(8, 25);
    const double gap = scene.Chance(0.4) ? scene.Uniform(2, 8) : 0.0;
    if (st.NearJunction(x, x + w, 2.0)) {
      x = std::max(x + 1.0, st.x_j + kWalk + 2.0);
      continue;
    }
    const double depth = scene.Uniform(8, 16), height = scene.Uniform(6, 25);
    const double setback = scene.Uniform(0, 2);
    const Eigen::Vector3d centre(x + 0.5 * w, side * (kWalk + setback + 0.5 * depth), 0.5 * height);
    std::vector<SceneQuad> box;
    // Texture before colour (see Rng::Color on argument order).
    const int texture = scene.Texture();
    const Eigen::Vector3f color = scene.Color(0.35f, 0.9f);
    AddBox(MakePose(Eigen::Matrix3d::Identity(), centre), {w, depth, height}, color, texture, &box, false);
    for (const auto& q : box) AddTiled(q, 10.0, &world->quads);
    x += w + gap;
  }
  for (double x = st.x_min + scene.Uniform(0, 10); x < st.x_max; x += scene.Uniform(12, 30)) {
    if (st.NearJunction(x, x, 2.0)) continue;
    const double h = scene.Uniform(3, 5);
    const int texture = scene.Texture();
    const Eigen::Vector3f color = scene.Color(0.1f, 0.4f);
    AddBox(MakePose(Eigen::Matrix3d::Identity(), {x, side * 10.8, 0.5 * h}), {0.25, 0.25, h},
           color, texture, &world->quads, false);
  }
  for (double x = st.x_min + 5; x < st.x_max; x += scene.Uniform(5.5, 9)) {
    if (st.NearJunction(x, x, 8.0) || !scene.Chance(0.45)) continue;
    const SceneBody parked = MakeCar(scene);
    const Pose g_from_car = MakePose(Rz(side < 0 ? 0.0 : kPi), {x, side * 8.25, 0});
    for (const auto& q : parked.quads) world->quads.push_back(q.Transformed(g_from_car));
  }
}

// Footprints as two discs each (front and back half of a car), so cars in neighbouring lanes
// may pass each other but never overlap.
using Footprint = std::array<Eigen::Vector2d, 2>;
Footprint Discs(const Eigen::Vector2d& centre, double heading) {
  const Eigen::Vector2d half(1.25 * std::cos(heading), 1.25 * std::sin(heading));
  return Footprint{centre + half, centre - half};
}
bool Overlap(const Footprint& a, const Footprint& b) {
  for (const auto& p : a)
    for (const auto& q : b)
      if ((p - q).norm() < 2.6) return true;
  return false;
}

// Cars sharing a lane share its pace (within ±0.4 m/s), so they rarely run into each other.
struct LanePaces {
  double same_outer = 0, oncoming_inner = 0, oncoming_outer = 0;
};

/// Where a moving car drives: its path, mean speed, and where it is at time t_ref.
struct CarRoute {
  std::vector<Eigen::Vector2d> waypoints;
  double v = 0, t_ref = 0;
  Eigen::Vector2d ref_point = Eigen::Vector2d::Zero();
};

// Same direction as the camera, oncoming, crossing the junction, or turning at it.
CarRoute DrawRoute(const Street& st, const CameraRun& cam, const std::vector<double>& t,
                   const LanePaces& pace, Rng& traj) {
  const int frames = static_cast<int>(t.size());
  CarRoute r;
  const double kind = traj.Uniform();
  if (kind < 0.3) {  // same direction as the camera, ahead or beside it
    const bool own_lane = traj.Chance(0.4);
    const double lane = own_lane ? -1.75 : -5.25;
    r.v = (own_lane ? cam.speed.v : pace.same_outer) + traj.Uniform(-0.4, 0.4);
    r.waypoints = {{st.x_min - 1000, lane}, {st.x_max + 1000, lane}};
    r.ref_point = {own_lane ? traj.Uniform(12, 45) : traj.Uniform(-15, 50), lane};
    r.t_ref = 0;
  } else if (kind < 0.65) {  // oncoming, meets the camera at t_ref
    const bool inner = traj.Chance(0.5);
    const double lane = inner ? 1.75 : 5.25;
    r.v = (inner ? pace.oncoming_inner : pace.oncoming_outer) + traj.Uniform(-0.4, 0.4);
    r.waypoints = {{st.x_max + 1000, lane}, {st.x_min - 1000, lane}};
    const int f_meet = traj.Int(frames / 6, frames - 1);
    r.ref_point = {cam.xy[f_meet].x(), lane};
    r.t_ref = t[f_meet];
  } else {  // through the junction, straight or turning into the main street
    const double dir = traj.Sign();  // +1: driving north (+y)
    const double x_lane = st.x_j + dir * (traj.Chance(0.5) ? 1.75 : 5.25);
    r.v = traj.Uniform(4, 12);
    r.waypoints = {{x_lane, -dir * 1000}};
    if (kind < 0.85) {
      r.waypoints.push_back({x_lane, dir * 1000});
    } else {
      r.v = std::min(r.v, 9.0);
      const double to_east = traj.Sign();  // +1: turns towards +x
      const double y_lane = to_east > 0 ? -5.25 : (traj.Chance(0.5) ? 1.75 : 5.25);
      r.waypoints.push_back({x_lane, y_lane});
      r.waypoints.push_back({x_lane + to_east * 1000, y_lane});
    }
    r.ref_point = {x_lane, r.waypoints.size() == 3 ? r.waypoints[1].y() : 0.0};
    r.t_ref = cam.TimeAt(st.x_j - traj.Uniform(15, 60), t);
  }
  r.v = std::clamp(r.v, 3.0, 15.0);
  return r;
}

/// One car's poses and footprints per frame along a drawn route.
struct CarPlan {
  std::vector<Pose> poses;
  std::vector<Footprint> footprint;
  int visible = -1;  ///< frames in view; -1: no collision-free plan
};

// Each plan is redrawn until the car keeps clear of the camera car and the other cars and
// stays in view for `min_visible` frames; the plan in view longest is kept.
CarPlan PlanCar(const Street& st, const CameraRun& cam, const std::vector<double>& t,
                const LanePaces& pace, const std::vector<Footprint>& cam_discs,
                const std::vector<std::vector<Footprint>>& accepted, const StereoCamera& camera,
                const Draft& d, int min_visible, Rng& traj) {
  const int frames = static_cast<int>(t.size());
  CarPlan best;
  std::vector<Pose> poses(frames);
  std::vector<Footprint> footprint(frames);
  for (int attempt = 0; attempt < 600 && best.visible < min_visible; ++attempt) {
    const CarRoute route = DrawRoute(st, cam, t, pace, traj);
    const Path path(route.waypoints, 7.0);
    const double s_ref = path.NearestS(route.ref_point);
    const SpeedProfile speed{route.v, 2 * kPi / traj.Uniform(5, 10), traj.Uniform(0, 2 * kPi)};
    int visible = 0;
    bool clear = true;
    for (int f = 0; f < frames && clear; ++f) {
      double heading = 0;
      Eigen::Vector2d xy;
      path.At(s_ref + speed.Distance(t[f], route.t_ref), &xy, &heading);
      poses[f] = MakePose(Rz(heading), {xy.x(), xy.y(), 0.0});
      footprint[f] = Discs(xy, heading);
      if (Overlap(footprint[f], cam_discs[f])) clear = false;
      for (const auto& other : accepted)
        if (Overlap(footprint[f], other[f])) clear = false;
      if (InFrustum(d.g_from_cam[f], camera, {xy.x(), xy.y(), 0.8}, 2.0, 50.0)) ++visible;
    }
    if (clear && visible > best.visible) {
      best.visible = visible;
      best.poses = poses;
      best.footprint = footprint;
    }
  }
  return best;
}

// Moving cars, each a body of its own with its poses.
void AddMovingCars(const Street& st, const CameraRun& cam, const std::vector<double>& t,
                   int num_cars, const StereoCamera& camera, Rng& scene, Rng& traj, Draft* d) {
  const int frames = static_cast<int>(t.size());
  const int min_visible = std::min(25, frames / 2);
  std::vector<Footprint> cam_discs(frames);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Vector3d fwd = d->g_from_cam[f].linear().col(2);
    const double heading = std::atan2(fwd.y(), fwd.x());
    cam_discs[f] = Discs(cam.xy[f] - 1.0 * Eigen::Vector2d(std::cos(heading), std::sin(heading)), heading);
  }
  std::vector<std::vector<Footprint>> accepted;
  LanePaces pace;
  pace.same_outer = std::clamp(cam.speed.v + traj.Uniform(-3, 3), 3.0, 15.0);
  pace.oncoming_inner = traj.Uniform(5, 14);
  pace.oncoming_outer = traj.Uniform(5, 14);
  for (int k = 0; k < num_cars; ++k) {
    SceneBody car = MakeCar(scene);
    CarPlan plan = PlanCar(st, cam, t, pace, cam_discs, accepted, camera, *d, min_visible, traj);
    if (plan.visible < min_visible)
      GetLogger("system")->warn("synthetic: car {} is in view in only {} frames", k + 1,
                                std::max(plan.visible, 0));
    if (plan.visible < 0) {  // no collision-free plan: park it far away, out of everyone's way
      plan.poses.assign(frames, MakePose(Eigen::Matrix3d::Identity(), {st.x_min - 200.0 - 10.0 * k, 0, 0}));
      plan.footprint.assign(frames, Discs({st.x_min - 200.0 - 10.0 * k, 0}, 0));
    }
    accepted.push_back(plan.footprint);
    d->geometry.bodies.push_back(std::move(car));
    d->g_from_object.push_back(std::move(plan.poses));
  }
}

}  // namespace

Draft BuildOutdoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj) {
  DraftStart start = StartDraft(kOutdoor, options, scene);
  Draft& d = start.draft;
  const std::vector<double>& t = start.t;
  const CameraRun run = DriveCamera(t, traj, &d);

  // Static world: main street along x, a cross street at x_j, sidewalks, yards, buildings,
  // poles and parked cars.
  Street st;
  st.x_j = run.speed.Distance(scene.Uniform(0.45, 0.8) * t.back(), 0.0);
  st.x_min = -60.0;
  st.x_max = run.xy.back().x() + 120.0;
  SceneBody world;
  world.kind = "static";
  AddGround(st, scene, &world);
  for (double side : {-1.0, 1.0}) AddStreetSide(st, side, scene, &world);
  d.geometry.bodies.push_back(std::move(world));
  d.g_from_object.push_back(std::vector<Pose>(t.size(), Pose::Identity()));

  AddMovingCars(st, run, t, start.objects, cam, scene, traj, &d);
  return std::move(d);
}

}  // namespace cslam::synthetic_detail
