#include "system/synthetic/synthetic_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"

namespace cslam {

void SyntheticOptions::Check() const {
  if (preset != "indoor" && preset != "outdoor")
    throw ConfigError("preset: must be 'indoor' or 'outdoor', got '" + preset + "'");
  CheckOption(frames == 0 || (frames >= 2 && frames <= 20000), "frames",
              "must be 0 (preset draws) or in [2, 20000]", frames);
  CheckOption(objects >= -1 && objects <= 30, "objects", "must be -1 (preset draws) or in [0, 30]",
              objects);
  CheckOption(std::isfinite(noise_px) && noise_px >= 0.0 && noise_px <= 3.0, "noise_px",
              "must be in [0, 3] px", noise_px);
  CheckOption(std::isfinite(landmark_density) && landmark_density > 0.0 && landmark_density <= 20.0,
              "landmark_density", "must be in (0, 20]", landmark_density);
}

void SyntheticOptions::Load(OptionsReader& reader) {
  reader.Read("preset", &preset);
  reader.Read("seed", &seed);
  reader.Read("frames", &frames);
  reader.Read("objects", &objects);
  reader.Read("noise_px", &noise_px);
  reader.Read("gaussian_noise", &gaussian_noise);
  reader.Read("landmark_density", &landmark_density);
}

double SyntheticSequence::CameraTravel() const {
  double travel = 0.0;
  for (size_t f = 1; f < world_from_cam.size(); ++f)
    travel += (world_from_cam[f].translation() - world_from_cam[f - 1].translation()).norm();
  return travel;
}

namespace {

constexpr double kPi = std::numbers::pi;
/// A track shorter than this carries no motion information; a frontend would drop it.
constexpr int kMinTrackLength = 2;
/// Near plane for clipping occluders, metres (surfaces closer than this to a lens are ignored).
constexpr double kNearClip = 1e-3;
/// Screen-space bin size of the occluder grid, px.
constexpr int kCellPx = 16;
/// Points keep this fraction of an edge away from their rectangle's border (no grazing rays).
constexpr double kEdgeMargin = 0.01;
/// Noise draws that would leave less disparity than this are redrawn (a matcher rejects them).
constexpr double kMinNoisyDisparityPx = 0.5;

/// One deterministic random stream (std::mt19937_64's output is fixed by the standard; the
/// distributions are ours so files are identical across standard libraries).
class Rng {
 public:
  Rng(int seed, uint64_t stream) {
    uint64_t z = static_cast<uint64_t>(static_cast<uint32_t>(seed)) * 0x9E3779B97F4A7C15ULL +
                 stream * 0xBF58476D1CE4E5B9ULL + 0x94D049BB133111EBULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    engine_.seed(z ^ (z >> 31));
  }
  /// Uniform in [a, b).
  double Uniform(double a = 0.0, double b = 1.0) {
    return a + (b - a) * (static_cast<double>(engine_() >> 11) * 0x1.0p-53);
  }
  /// Uniform integer in [lo, hi].
  int Int(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
  }
  bool Chance(double p) { return Uniform() < p; }
  double Sign() { return Chance(0.5) ? 1.0 : -1.0; }
  double Normal() {
    const double u1 = 1.0 - Uniform(), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  Eigen::Vector3f Color(float lo, float hi) {
    // One draw per statement: the order of function arguments is unspecified (gcc and clang
    // differ), and the files must not depend on the compiler. Draws run z, y, x, as gcc did.
    const float z = static_cast<float>(Uniform(lo, hi));
    const float y = static_cast<float>(Uniform(lo, hi));
    const float x = static_cast<float>(Uniform(lo, hi));
    return Eigen::Vector3f(x, y, z);
  }
  int Texture() { return Int(0, (1 << 30) - 1); }

 private:
  std::mt19937_64 engine_;
};

/// Per-preset constants (the paper's protocol where it states one).
struct Preset {
  double rate_hz;
  double baseline_m;
  double min_depth_m, max_depth_m;  ///< depth range a stereo matcher would accept
  int min_frames, max_frames;
  int min_objects, max_objects;
  double static_density;  ///< surface points per m² on the static world
  double object_density;  ///< surface points per m² on moving bodies
  double min_density_scale, max_density_scale;  ///< per-sequence spread of the densities
};

constexpr Preset kOutdoor{10.0, 0.50, 1.0, 55.0, 200, 750, 5, 10, 0.16, 2.5, 0.6, 1.6};
constexpr Preset kIndoor{30.0, 0.10, 0.3, 8.0, 190, 300, 2, 5, 5.0, 40.0, 0.6, 1.6};

StereoCamera PaperCamera(double baseline) {
  StereoCamera cam;
  cam.fx = cam.fy = 640.0;  // 1280 px wide, horizontal FOV 90°
  cam.cx = 639.5;
  cam.cy = 359.5;
  cam.width = 1280;
  cam.height = 720;
  cam.baseline = baseline;
  return cam;
}

Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }

Pose MakePose(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = r;
  p.translation() = t;
  return p;
}

/// Ground frame G (x east, y north, z up) pose of a camera at `position` looking along
/// `forward`, rolled by `roll` about the optical axis. Camera axes: x right, y down, z forward.
Pose CameraPose(const Eigen::Vector3d& position, const Eigen::Vector3d& forward, double roll) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r << x, y, z;
  return MakePose(r * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).matrix(), position);
}

/// True when a point (ground frame) is in the camera's field of view within a depth range.
bool InFrustum(const Pose& g_from_cam, const StereoCamera& cam, const Eigen::Vector3d& p_in_g,
               double min_depth, double max_depth) {
  const Eigen::Vector3d p = g_from_cam.inverse() * p_in_g;
  if (p.z() < min_depth || p.z() > max_depth) return false;
  return std::abs(p.x() / p.z()) < cam.cx / cam.fx && std::abs(p.y() / p.z()) < cam.cy / cam.fy;
}

/// Splits a rectangle into tiles no longer than `max_edge` metres (separate textures, so a
/// renderer's texture resolution stays reasonable on large surfaces).
void AddTiled(const SceneQuad& quad, double max_edge, std::vector<SceneQuad>* quads) {
  const int nu = std::max(1, static_cast<int>(std::ceil(quad.edge_u.norm() / max_edge)));
  const int nv = std::max(1, static_cast<int>(std::ceil(quad.edge_v.norm() / max_edge)));
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      SceneQuad q = quad;
      q.origin = quad.At(static_cast<double>(i) / nu, static_cast<double>(j) / nv);
      q.edge_u = quad.edge_u / nu;
      q.edge_v = quad.edge_v / nv;
      q.texture = quad.texture + i * nv + j;
      quads->push_back(q);
    }
  }
}

/// A horizontal ground rectangle [x0,x1]×[y0,y1] at height z, facing up.
SceneQuad GroundQuad(double x0, double x1, double y0, double y1, double z,
                     const Eigen::Vector3f& color, int texture) {
  SceneQuad q;
  q.origin = Eigen::Vector3d(x0, y0, z);
  q.edge_u = Eigen::Vector3d(x1 - x0, 0, 0);
  q.edge_v = Eigen::Vector3d(0, y1 - y0, 0);
  q.color = color;
  q.texture = texture;
  return q;
}

/// A planar path through waypoints with rounded corners, parameterised by arc length; beyond
/// its ends it continues straight.
class Path {
 public:
  Path(const std::vector<Eigen::Vector2d>& waypoints, double corner_radius) {
    std::vector<Eigen::Vector2d> pts{waypoints.front()};
    for (size_t i = 1; i + 1 < waypoints.size(); ++i) {
      const Eigen::Vector2d in = waypoints[i] - waypoints[i - 1], out = waypoints[i + 1] - waypoints[i];
      const double turn = std::acos(std::clamp(in.normalized().dot(out.normalized()), -1.0, 1.0));
      const double cut = std::min({corner_radius * std::tan(0.5 * turn), 0.45 * in.norm(),
                                   0.45 * out.norm()});
      const Eigen::Vector2d a = waypoints[i] - in.normalized() * cut;
      const Eigen::Vector2d b = waypoints[i] + out.normalized() * cut;
      for (int k = 0; k <= 32; ++k) {  // quadratic Bézier: tangent-continuous corner
        const double s = k / 32.0;
        pts.push_back((1 - s) * (1 - s) * a + 2 * s * (1 - s) * waypoints[i] + s * s * b);
      }
    }
    pts.push_back(waypoints.back());
    for (const auto& p : pts) {
      if (!points_.empty() && (p - points_.back()).norm() < 1e-9) continue;
      s_.push_back(points_.empty() ? 0.0 : s_.back() + (p - points_.back()).norm());
      points_.push_back(p);
    }
  }

  /// Position and heading (radians from +x) at arc length s.
  void At(double s, Eigen::Vector2d* p, double* heading) const {
    size_t i = std::upper_bound(s_.begin(), s_.end(), s) - s_.begin();
    i = std::clamp<size_t>(i, 1, s_.size() - 1);
    const Eigen::Vector2d d = points_[i] - points_[i - 1];
    const double len = s_[i] - s_[i - 1];
    *p = points_[i - 1] + d * ((s - s_[i - 1]) / len);
    // Blend the headings of neighbouring segments so the heading is continuous at vertices.
    const double frac = std::clamp((s - s_[i - 1]) / len, 0.0, 1.0);
    auto seg_heading = [&](size_t k) {
      const Eigen::Vector2d e = points_[k] - points_[k - 1];
      return std::atan2(e.y(), e.x());
    };
    const double h = seg_heading(i);
    double h_prev = i >= 2 ? seg_heading(i - 1) : h;
    double h_next = i + 1 < points_.size() ? seg_heading(i + 1) : h;
    auto wrap = [](double a) { return std::remainder(a, 2 * kPi); };
    const double at_start = h + 0.5 * wrap(h_prev - h), at_end = h + 0.5 * wrap(h_next - h);
    *heading = (s < 0 || s > s_.back()) ? h : at_start + frac * wrap(at_end - at_start);
  }

  /// Arc length of the path point nearest to `q`.
  double NearestS(const Eigen::Vector2d& q) const {
    double best_s = 0, best_d2 = 1e300;
    for (size_t i = 1; i < points_.size(); ++i) {
      const Eigen::Vector2d e = points_[i] - points_[i - 1];
      const double a = std::clamp((q - points_[i - 1]).dot(e) / e.squaredNorm(), 0.0, 1.0);
      const double d2 = (points_[i - 1] + a * e - q).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best_s = s_[i - 1] + a * (s_[i] - s_[i - 1]);
    }
    return best_s;
  }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> s_;
};

/// The scene in its own ground frame G before the world is re-based on camera 0.
struct Draft {
  double rate_hz = 10;
  std::vector<Pose> g_from_cam;
  SceneGeometry geometry;                         // body 0 in G, others in their own frames
  std::vector<std::vector<Pose>> g_from_object;   // [object][frame], object 0 identity
};

std::vector<double> Times(int frames, double rate) {
  std::vector<double> t(frames);
  for (int f = 0; f < frames; ++f) t[f] = f / rate;
  return t;
}

/// A car body in its own frame: x forward, y left, z up, origin on the ground at its centre.
SceneBody MakeCar(Rng& scene) {
  SceneBody car;
  car.kind = "car";
  const double length = scene.Uniform(3.8, 4.8), width = scene.Uniform(1.7, 1.9);
  const Eigen::Vector3f paint = scene.Color(0.1f, 0.9f);
  const Eigen::Vector3f glass(0.15f, 0.18f, 0.22f), tyre(0.05f, 0.05f, 0.05f);
  AddBox(MakePose(Eigen::Matrix3d::Identity(), {0, 0, 0.675}), {length, width, 0.75}, paint,
         scene.Texture(), &car.quads);
  AddBox(MakePose(Eigen::Matrix3d::Identity(), {-0.08 * length, 0, 1.275}),
         {0.55 * length, width - 0.12, 0.45}, glass, scene.Texture(), &car.quads, false);
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      AddBox(MakePose(Eigen::Matrix3d::Identity(), {sx * 0.32 * length, sy * (0.5 * width - 0.12), 0.3}),
             {0.62, 0.24, 0.6}, tyre, scene.Texture(), &car.quads, false);
  return car;
}

/// Smooth speed profile: distance travelled since t_ref at mean speed v with ±10 % variation.
struct SpeedProfile {
  double v = 0, omega = 1, phase = 0;
  double Distance(double t, double t_ref) const {
    const double amp = 0.1 * v / omega;
    return v * (t - t_ref) - amp * (std::cos(omega * t + phase) - std::cos(omega * t_ref + phase));
  }
};

Draft BuildOutdoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj) {
  Draft d;
  d.rate_hz = kOutdoor.rate_hz;
  // Both counts are always drawn, so overriding one leaves the rest of the scene unchanged.
  const int drawn_frames = scene.Int(kOutdoor.min_frames, kOutdoor.max_frames);
  const int drawn_objects = scene.Int(kOutdoor.min_objects, kOutdoor.max_objects);
  const int frames = options.frames > 0 ? options.frames : drawn_frames;
  const std::vector<double> t = Times(frames, d.rate_hz);
  const double duration = t.back();

  // Camera: a car-mounted rig 1.6 m above the road, inner lane, 5–12 m/s, chosen so a full-length
  // sequence travels 120–480 m like the paper's.
  double v_lo = std::max(5.0, 120.0 / duration), v_hi = std::min(12.0, 480.0 / duration);
  if (v_lo > v_hi) v_lo = 5.0, v_hi = 12.0;
  const double v_cam = traj.Uniform(v_lo, v_hi);
  const SpeedProfile cam_speed{v_cam, 2 * kPi / traj.Uniform(8, 15), traj.Uniform(0, 2 * kPi)};
  const double lat_amp = traj.Uniform(0.05, 0.2), lat_w = 2 * kPi / traj.Uniform(6, 12),
               lat_phase = traj.Uniform(0, 2 * kPi);
  const double bob_phase = traj.Uniform(0, 2 * kPi), pitch0 = traj.Uniform(-0.03, 0.0);
  std::vector<Eigen::Vector2d> cam_xy(frames);
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
    cam_xy[f] = {x, y};
    d.g_from_cam.push_back(CameraPose({x, y, z}, forward, 0.003 * std::sin(2 * kPi * 0.9 * t[f])));
  }
  const double x_end_cam = cam_xy.back().x();

  // Static world: main street along x, a cross street at x_j, sidewalks, yards, buildings,
  // poles and parked cars (parked cars are static: label 0).
  const double x_j = cam_speed.Distance(scene.Uniform(0.45, 0.8) * duration, 0.0);
  const double x_min = -60.0, x_max = x_end_cam + 120.0;
  constexpr double kRoad = 9.5, kWalk = 12.5, kYard = 40.0, kCross = 150.0;
  SceneBody world;
  world.kind = "static";
  const Eigen::Vector3f asphalt(0.3f, 0.3f, 0.32f), pavement(0.62f, 0.6f, 0.57f),
      grass(0.3f, 0.45f, 0.2f);
  AddTiled(GroundQuad(x_min, x_max, -kRoad, kRoad, 0, asphalt, scene.Texture()), 20.0, &world.quads);
  for (auto [a, b] : {std::pair{x_min, x_j - kWalk}, std::pair{x_j + kWalk, x_max}}) {
    if (b <= a) continue;
    for (double s : {-1.0, 1.0}) {
      const double y_in = s * kRoad, y_walk = s * kWalk, y_yard = s * kYard;
      AddTiled(GroundQuad(a, b, std::min(y_in, y_walk), std::max(y_in, y_walk), 0, pavement,
                          scene.Texture()), 20.0, &world.quads);
      AddTiled(GroundQuad(a, b, std::min(y_walk, y_yard), std::max(y_walk, y_yard), 0, grass,
                          scene.Texture()), 20.0, &world.quads);
    }
  }
  for (double s : {-1.0, 1.0}) {
    const double y0 = std::min(s * kRoad, s * kCross), y1 = std::max(s * kRoad, s * kCross);
    AddTiled(GroundQuad(x_j - kRoad, x_j + kRoad, y0, y1, 0, asphalt, scene.Texture()), 20.0,
             &world.quads);
    AddTiled(GroundQuad(x_j - kWalk, x_j - kRoad, y0, y1, 0, pavement, scene.Texture()), 20.0,
             &world.quads);
    AddTiled(GroundQuad(x_j + kRoad, x_j + kWalk, y0, y1, 0, pavement, scene.Texture()), 20.0,
             &world.quads);
  }
  auto near_junction = [&](double a, double b, double margin) {
    return b > x_j - kWalk - margin && a < x_j + kWalk + margin;
  };
  for (double side : {-1.0, 1.0}) {
    for (double x = x_min; x < x_max;) {
      const double w = scene.Uniform(8, 25);
      const double gap = scene.Chance(0.4) ? scene.Uniform(2, 8) : 0.0;
      if (near_junction(x, x + w, 2.0)) {
        x = std::max(x + 1.0, x_j + kWalk + 2.0);
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
      for (const auto& q : box) AddTiled(q, 10.0, &world.quads);
      x += w + gap;
    }
    for (double x = x_min + scene.Uniform(0, 10); x < x_max; x += scene.Uniform(12, 30)) {
      if (near_junction(x, x, 2.0)) continue;
      const double h = scene.Uniform(3, 5);
      const int texture = scene.Texture();
      const Eigen::Vector3f color = scene.Color(0.1f, 0.4f);
      AddBox(MakePose(Eigen::Matrix3d::Identity(), {x, side * 10.8, 0.5 * h}), {0.25, 0.25, h},
             color, texture, &world.quads, false);
    }
    for (double x = x_min + 5; x < x_max; x += scene.Uniform(5.5, 9)) {
      if (near_junction(x, x, 8.0) || !scene.Chance(0.45)) continue;
      const SceneBody parked = MakeCar(scene);
      const Pose g_from_car = MakePose(Rz(side < 0 ? 0.0 : kPi), {x, side * 8.25, 0});
      for (const auto& q : parked.quads) world.quads.push_back(q.Transformed(g_from_car));
    }
  }
  d.geometry.bodies.push_back(std::move(world));
  d.g_from_object.push_back(std::vector<Pose>(frames, Pose::Identity()));

  // Moving cars: same direction, oncoming, crossing the junction, turning at it. Each plan is
  // redrawn until the car keeps clear of the camera car and the other cars and stays in view
  // for tens of frames.
  auto time_cam_at = [&](double x) {
    int f = 0;
    while (f + 1 < frames && cam_xy[f].x() < x) ++f;
    return t[f] - (cam_xy[f].x() - x) / v_cam;
  };
  const int num_cars = options.objects >= 0 ? options.objects : drawn_objects;
  const int min_visible = std::min(25, frames / 2);
  // Footprints as two discs each (front and back half of a car), so cars in neighbouring lanes
  // may pass each other but never overlap.
  auto discs = [](const Eigen::Vector2d& centre, double heading) {
    const Eigen::Vector2d half(1.25 * std::cos(heading), 1.25 * std::sin(heading));
    return std::array<Eigen::Vector2d, 2>{centre + half, centre - half};
  };
  auto overlap = [](const std::array<Eigen::Vector2d, 2>& a, const std::array<Eigen::Vector2d, 2>& b) {
    for (const auto& p : a)
      for (const auto& q : b)
        if ((p - q).norm() < 2.6) return true;
    return false;
  };
  std::vector<std::array<Eigen::Vector2d, 2>> cam_discs(frames);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Vector3d fwd = d.g_from_cam[f].linear().col(2);
    const double heading = std::atan2(fwd.y(), fwd.x());
    cam_discs[f] = discs(cam_xy[f] - 1.0 * Eigen::Vector2d(std::cos(heading), std::sin(heading)), heading);
  }
  std::vector<std::vector<std::array<Eigen::Vector2d, 2>>> accepted;
  // Cars sharing a lane share its pace (within ±0.4 m/s), so they rarely run into each other.
  const double v_same_outer = std::clamp(v_cam + traj.Uniform(-3, 3), 3.0, 15.0);
  const double v_oncoming_inner = traj.Uniform(5, 14), v_oncoming_outer = traj.Uniform(5, 14);
  for (int k = 0; k < num_cars; ++k) {
    SceneBody car = MakeCar(scene);
    std::vector<Pose> poses(frames), best_poses;
    std::vector<std::array<Eigen::Vector2d, 2>> footprint(frames), best_footprint;
    int best_visible = -1;
    for (int attempt = 0; attempt < 600 && best_visible < min_visible; ++attempt) {
      const double kind = traj.Uniform();
      std::vector<Eigen::Vector2d> waypoints;
      double v = 0, t_ref = 0, s_ref = 0;
      Eigen::Vector2d ref_point;
      if (kind < 0.3) {  // same direction as the camera, ahead or beside it
        const bool own_lane = traj.Chance(0.4);
        const double lane = own_lane ? -1.75 : -5.25;
        v = (own_lane ? v_cam : v_same_outer) + traj.Uniform(-0.4, 0.4);
        waypoints = {{x_min - 1000, lane}, {x_max + 1000, lane}};
        ref_point = {own_lane ? traj.Uniform(12, 45) : traj.Uniform(-15, 50), lane};
        t_ref = 0;
      } else if (kind < 0.65) {  // oncoming, meets the camera at t_ref
        const bool inner = traj.Chance(0.5);
        const double lane = inner ? 1.75 : 5.25;
        v = (inner ? v_oncoming_inner : v_oncoming_outer) + traj.Uniform(-0.4, 0.4);
        waypoints = {{x_max + 1000, lane}, {x_min - 1000, lane}};
        const int f_meet = traj.Int(frames / 6, frames - 1);
        ref_point = {cam_xy[f_meet].x(), lane};
        t_ref = t[f_meet];
      } else {  // through the junction, straight or turning into the main street
        const double dir = traj.Sign();  // +1: driving north (+y)
        const double x_lane = x_j + dir * (traj.Chance(0.5) ? 1.75 : 5.25);
        v = traj.Uniform(4, 12);
        waypoints = {{x_lane, -dir * 1000}};
        if (kind < 0.85) {
          waypoints.push_back({x_lane, dir * 1000});
        } else {
          v = std::min(v, 9.0);
          const double to_east = traj.Sign();  // +1: turns towards +x
          const double y_lane = to_east > 0 ? -5.25 : (traj.Chance(0.5) ? 1.75 : 5.25);
          waypoints.push_back({x_lane, y_lane});
          waypoints.push_back({x_lane + to_east * 1000, y_lane});
        }
        ref_point = {x_lane, waypoints.size() == 3 ? waypoints[1].y() : 0.0};
        t_ref = time_cam_at(x_j - traj.Uniform(15, 60));
      }
      v = std::clamp(v, 3.0, 15.0);
      const Path path(waypoints, 7.0);
      s_ref = path.NearestS(ref_point);
      const SpeedProfile speed{v, 2 * kPi / traj.Uniform(5, 10), traj.Uniform(0, 2 * kPi)};
      int visible = 0;
      bool clear = true;
      for (int f = 0; f < frames && clear; ++f) {
        double heading = 0;
        Eigen::Vector2d xy;
        path.At(s_ref + speed.Distance(t[f], t_ref), &xy, &heading);
        poses[f] = MakePose(Rz(heading), {xy.x(), xy.y(), 0.0});
        footprint[f] = discs(xy, heading);
        if (overlap(footprint[f], cam_discs[f])) clear = false;
        for (const auto& other : accepted)
          if (overlap(footprint[f], other[f])) clear = false;
        if (InFrustum(d.g_from_cam[f], cam, {xy.x(), xy.y(), 0.8}, 2.0, 50.0)) ++visible;
      }
      if (clear && visible > best_visible) {
        best_visible = visible;
        best_poses = poses;
        best_footprint = footprint;
      }
    }
    if (best_visible < min_visible)
      GetLogger("system")->warn("synthetic: car {} is in view in only {} frames", k + 1,
                                std::max(best_visible, 0));
    if (best_visible < 0) {  // no collision-free plan: park it far away, out of everyone's way
      best_poses.assign(frames, MakePose(Eigen::Matrix3d::Identity(), {x_min - 200.0 - 10.0 * k, 0, 0}));
      best_footprint.assign(frames, discs({x_min - 200.0 - 10.0 * k, 0}, 0));
    }
    accepted.push_back(best_footprint);
    d.geometry.bodies.push_back(std::move(car));
    d.g_from_object.push_back(std::move(best_poses));
  }
  return d;
}

Draft BuildIndoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj) {
  Draft d;
  d.rate_hz = kIndoor.rate_hz;
  // Both counts are always drawn, so overriding one leaves the rest of the scene unchanged.
  const int drawn_frames = scene.Int(kIndoor.min_frames, kIndoor.max_frames);
  const int drawn_objects = scene.Int(kIndoor.min_objects, kIndoor.max_objects);
  const int frames = options.frames > 0 ? options.frames : drawn_frames;
  const std::vector<double> t = Times(frames, d.rate_hz);

  // Room [-W/2, W/2] × [-D/2, D/2] × [0, H], seen from inside; furniture along the walls.
  const double W = scene.Uniform(6, 10), D = scene.Uniform(6, 9), H = scene.Uniform(2.6, 3.2);
  SceneBody room;
  room.kind = "static";
  {
    std::vector<SceneQuad> shell;
    const int texture = scene.Texture();
    const Eigen::Vector3f color = scene.Color(0.5f, 0.9f);
    AddBox(MakePose(Eigen::Matrix3d::Identity(), {0, 0, 0.5 * H}), {W, D, H}, color, texture, &shell,
           true, true);
    for (auto& q : shell) {
      q.color = scene.Color(0.4f, 0.9f);
      q.texture = scene.Texture();
      AddTiled(q, 2.0, &room.quads);
    }
  }
  auto add_box = [&](const Pose& g_from_item, const Eigen::Vector3d& centre,
                     const Eigen::Vector3d& size, const Eigen::Vector3f& color) {
    AddBox(g_from_item * MakePose(Eigen::Matrix3d::Identity(), centre), size, color,
           scene.Texture(), &room.quads, false);
  };
  for (int wall = 0; wall < 4; ++wall) {
    // Wall frame: x along the wall, y into the room, z up; origin at the wall's left end.
    const double len = wall % 2 == 0 ? W : D, half_other = wall % 2 == 0 ? 0.5 * D : 0.5 * W;
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
  d.geometry.bodies.push_back(std::move(room));
  d.g_from_object.push_back(std::vector<Pose>(frames, Pose::Identity()));

  // Camera: hand-held, walking to and fro along the near side of the room (0.3–2.1 m/s mean
  // speed), looking into the far half where the objects move, with small smooth wobbles.
  const double span = traj.Uniform(0.5, 1.0) * (0.5 * W - 1.3);
  const double v_cam = traj.Uniform(0.3, 2.1);
  const double omega_cam = std::min(2.0, v_cam * kPi / (2 * span)), phase_cam = traj.Uniform(0, 2 * kPi);
  const double y_cam = -0.5 * D + traj.Uniform(1.2, 1.4), h0 = traj.Uniform(1.3, 1.7);
  Eigen::Matrix<double, 8, 2> wob;  // (omega, phase) of the wobbles
  for (int i = 0; i < 8; ++i) wob.row(i) << 2 * kPi / traj.Uniform(1.5, 8), traj.Uniform(0, 2 * kPi);
  auto wobble = [&](int i, double time) { return std::sin(wob(i, 0) * time + wob(i, 1)); };
  std::vector<Eigen::Vector3d> cam_pos(frames);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Vector3d pos(span * std::sin(omega_cam * t[f] + phase_cam), y_cam + 0.2 * wobble(5, t[f]),
                              h0 + 0.06 * wobble(0, t[f]));
    const Eigen::Vector3d target(0.3 * pos.x() + 0.6 * wobble(1, t[f]), 0.25 * D + 0.5 * wobble(2, t[f]),
                                 0.7 + 0.2 * wobble(3, t[f]));
    cam_pos[f] = pos;
    d.g_from_cam.push_back(CameraPose(pos, target - pos, 0.03 * wobble(4, t[f])));
  }

  // Moving objects: one or two stacked boxes each, drifting smoothly (0.1–1 m/s) and turning.
  const int num_objects = options.objects >= 0 ? options.objects : drawn_objects;
  const int min_visible = static_cast<int>(0.6 * frames);
  std::vector<std::pair<std::vector<Eigen::Vector3d>, double>> accepted;
  for (int k = 0; k < num_objects; ++k) {
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
    double radius = 0.5 * size.norm();
    if (scene.Chance(0.5)) {
      const double top_z = scene.Uniform(0.1, 0.3), top_y = scene.Uniform(0.1, 1.0) * size.y(),
                   top_x = scene.Uniform(0.1, 1.0) * size.x();
      const Eigen::Vector3d top(top_x, top_y, top_z);
      const int texture = scene.Texture();
      const Eigen::Vector3f color = scene.Color(0.1f, 1.0f);
      AddBox(MakePose(Eigen::Matrix3d::Identity(), {0, 0, 0.5 * (size.z() + top.z())}), top, color,
             texture, &body.quads, false);
      radius = std::max(radius, (Eigen::Vector3d(0.5 * size.x(), 0.5 * size.y(), 0.5 * size.z() + top.z())).norm());
    }
    std::vector<Pose> poses(frames), best_poses;
    std::vector<Eigen::Vector3d> centre(frames), best_centre;
    int best_visible = -1;
    for (int attempt = 0; attempt < 1000 && best_visible < min_visible; ++attempt) {
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
      const double z_lo = radius + 0.05 + sway, z_hi = std::min(1.5, H - 0.3 - radius - sway);
      const double c0_z = z_hi > z_lo ? traj.Uniform(z_lo, z_hi) : z_lo;
      const double c0_y = traj.Uniform(y_cam + 0.9, 0.5 * D - 1.0);
      const double c0_x = traj.Uniform(-0.5, 0.5) * (W - 2.4);
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
        if (std::abs(c.x()) > 0.5 * W - 1.0 - radius || c.y() > 0.5 * D - 1.0 - radius ||
            c.y() < y_cam + 0.6 + radius ||
            c.z() < radius + 0.02 || c.z() > H - 0.3 - radius)
          ok = false;
        if ((c - cam_pos[f]).norm() < radius + 0.5) ok = false;
        for (const auto& [other, other_radius] : accepted)
          if ((c - other[f]).norm() < radius + other_radius + 0.05) ok = false;
        if (InFrustum(d.g_from_cam[f], cam, c, 0.5, 7.0)) ++visible;
      }
      if (ok && visible > best_visible) {
        best_visible = visible;
        best_poses = poses;
        best_centre = centre;
      }
    }
    if (best_visible < min_visible)
      GetLogger("system")->warn("synthetic: object {} is in view in only {} frames", k + 1,
                                std::max(best_visible, 0));
    if (best_visible < 0) {  // no plan kept clear of everything: keep the last one
      best_poses = poses;
      best_centre = centre;
    }
    accepted.emplace_back(best_centre, radius);
    d.geometry.bodies.push_back(std::move(body));
    d.g_from_object.push_back(std::move(best_poses));
  }
  return d;
}

/// A quad posed in the left camera frame, with what the ray test needs precomputed.
struct CamQuad {
  Eigen::Vector3d origin, u, v, n;
  double inv_uu = 0, inv_vv = 0;
};

/// t in (0, t_max) where the segment from c to p crosses the quad, else false.
bool Blocks(const CamQuad& q, const Eigen::Vector3d& c, const Eigen::Vector3d& p, double t_max) {
  const Eigen::Vector3d d = p - c;
  const double denom = q.n.dot(d);
  if (denom == 0.0) return false;
  const double t = q.n.dot(q.origin - c) / denom;
  if (!(t > 0.0 && t < t_max)) return false;
  const Eigen::Vector3d x = c + t * d - q.origin;
  const double s = x.dot(q.u) * q.inv_uu, r = x.dot(q.v) * q.inv_vv;
  return s >= 0.0 && s <= 1.0 && r >= 0.0 && r <= 1.0;
}

/// Screen-space bins of the quads whose (near-clipped) projection overlaps each bin, for one
/// camera centred at (cam_x, 0, 0) in the left camera frame.
class OccluderGrid {
 public:
  OccluderGrid(const StereoCamera& cam, double cam_x)
      : cam_(cam), cam_x_(cam_x), cols_((cam.width + kCellPx - 1) / kCellPx),
        rows_((cam.height + kCellPx - 1) / kCellPx), cells_(cols_ * rows_) {}

  void Build(const std::vector<CamQuad>& quads) {
    for (auto& c : cells_) c.clear();
    for (size_t k = 0; k < quads.size(); ++k) {
      const CamQuad& q = quads[k];
      const Eigen::Vector3d corners[4] = {q.origin, q.origin + q.u, q.origin + q.u + q.v, q.origin + q.v};
      double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
      bool any = false;
      auto add = [&](const Eigen::Vector3d& p) {
        const double u = cam_.fx * (p.x() - cam_x_) / p.z() + cam_.cx;
        const double v = cam_.fy * p.y() / p.z() + cam_.cy;
        u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
        any = true;
      };
      for (int i = 0; i < 4; ++i) {  // clip the polygon against z >= near
        const Eigen::Vector3d& a = corners[i];
        const Eigen::Vector3d& b = corners[(i + 1) % 4];
        if (a.z() >= kNearClip) add(a);
        if ((a.z() >= kNearClip) != (b.z() >= kNearClip))
          add(a + (b - a) * ((kNearClip - a.z()) / (b.z() - a.z())));
      }
      if (!any || u1 < 0 || v1 < 0 || u0 > cam_.width || v0 > cam_.height) continue;
      const int c0 = Col(u0), c1 = Col(u1), r0 = Row(v0), r1 = Row(v1);
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) cells_[r * cols_ + c].push_back(static_cast<int>(k));
    }
  }

  const std::vector<int>& At(double u, double v) const { return cells_[Row(v) * cols_ + Col(u)]; }

 private:
  int Col(double u) const { return std::clamp(static_cast<int>(std::floor(u / kCellPx)), 0, cols_ - 1); }
  int Row(double v) const { return std::clamp(static_cast<int>(std::floor(v / kCellPx)), 0, rows_ - 1); }
  StereoCamera cam_;
  double cam_x_;
  int cols_, rows_;
  std::vector<std::vector<int>> cells_;
};

/// A point sampled on a body's surface.
struct SurfacePoint {
  int object = 0;
  Eigen::Vector3d p_in_object;
};

/// One frame's visible surface points with their exact projections.
struct Sighting {
  int point = 0;
  int run = -1;  ///< index of the visibility run (tracklet) it belongs to
  Eigen::Vector3d x;
};

}  // namespace

SyntheticSequence GenerateSynthetic(const SyntheticOptions& options) {
  options.Check();
  const Timer timer;
  const bool outdoor = options.preset == "outdoor";
  const Preset& preset = outdoor ? kOutdoor : kIndoor;
  Rng scene_rng(options.seed, 1), traj_rng(options.seed, 2), landmark_rng(options.seed, 3),
      noise_rng(options.seed, 4);

  SyntheticSequence seq;
  seq.name = options.preset + "_seed" + std::to_string(options.seed);
  seq.camera = PaperCamera(preset.baseline_m);
  const double density_scale =
      options.landmark_density * scene_rng.Uniform(preset.min_density_scale, preset.max_density_scale);
  Draft draft = outdoor ? BuildOutdoor(options, seq.camera, scene_rng, traj_rng)
                        : BuildIndoor(options, seq.camera, scene_rng, traj_rng);
  const int frames = static_cast<int>(draft.g_from_cam.size());
  const int objects = static_cast<int>(draft.g_from_object.size());

  // Re-base everything on the left camera at frame 0.
  const Pose cam0_from_g = draft.g_from_cam[0].inverse();
  seq.timestamps = Times(frames, draft.rate_hz);
  for (int f = 0; f < frames; ++f)
    seq.world_from_cam.push_back(f == 0 ? Pose::Identity() : cam0_from_g * draft.g_from_cam[f]);
  seq.world_from_object.assign(objects, std::vector<Pose>(frames, Pose::Identity()));
  for (int o = 1; o < objects; ++o)
    for (int f = 0; f < frames; ++f) seq.world_from_object[o][f] = cam0_from_g * draft.g_from_object[o][f];
  seq.geometry = std::move(draft.geometry);
  for (auto& q : seq.geometry.bodies[0].quads) q = q.Transformed(cam0_from_g);

  // Surface points, grouped by quad so whole back-facing or off-screen quads are skipped.
  std::vector<SurfacePoint> points;
  std::vector<std::vector<std::vector<int>>> points_of_quad(objects);
  for (int o = 0; o < objects; ++o) {
    const auto& quads = seq.geometry.bodies[o].quads;
    points_of_quad[o].resize(quads.size());
    const double density = (o == 0 ? preset.static_density : preset.object_density) * density_scale;
    for (size_t q = 0; q < quads.size(); ++q) {
      const double expected = quads[q].Area() * density;
      const int n = static_cast<int>(expected) + (landmark_rng.Uniform() < expected - std::floor(expected));
      for (int i = 0; i < n; ++i) {
        const double a = landmark_rng.Uniform(kEdgeMargin, 1 - kEdgeMargin);
        const double b = landmark_rng.Uniform(kEdgeMargin, 1 - kEdgeMargin);
        points_of_quad[o][q].push_back(static_cast<int>(points.size()));
        points.push_back({o, quads[q].At(a, b)});
      }
    }
  }

  // Visibility per frame: in both images, in the depth range, surface facing both cameras, ray
  // to each camera unobstructed (checked against the quads binned under the point's pixel).
  const StereoCamera& cam = seq.camera;
  const Eigen::Vector3d centre_left = Eigen::Vector3d::Zero(), centre_right(cam.baseline, 0, 0);
  OccluderGrid grid_left(cam, 0.0), grid_right(cam, cam.baseline);
  std::vector<std::vector<Sighting>> sightings(frames);
  std::vector<CamQuad> cam_quads;
  std::vector<std::pair<int, int>> quad_ids;  // flat index -> (object, quad)
  for (int f = 0; f < frames; ++f) {
    const Pose cam_from_world = seq.world_from_cam[f].inverse();
    cam_quads.clear();
    quad_ids.clear();
    std::vector<Pose> cam_from_object(objects);
    for (int o = 0; o < objects; ++o) {
      cam_from_object[o] = cam_from_world * seq.world_from_object[o][f];
      const auto& quads = seq.geometry.bodies[o].quads;
      for (size_t q = 0; q < quads.size(); ++q) {
        const SceneQuad posed = quads[q].Transformed(cam_from_object[o]);
        CamQuad cq{posed.origin, posed.edge_u, posed.edge_v, posed.edge_u.cross(posed.edge_v),
                   1.0 / posed.edge_u.squaredNorm(), 1.0 / posed.edge_v.squaredNorm()};
        cam_quads.push_back(cq);
        quad_ids.emplace_back(o, static_cast<int>(q));
      }
    }
    grid_left.Build(cam_quads);
    grid_right.Build(cam_quads);
    for (size_t k = 0; k < cam_quads.size(); ++k) {
      const CamQuad& cq = cam_quads[k];
      if (cq.n.dot(centre_left - cq.origin) <= 0 || cq.n.dot(centre_right - cq.origin) <= 0) continue;
      const auto [o, q] = quad_ids[k];
      for (int idx : points_of_quad[o][q]) {
        const Eigen::Vector3d p = cam_from_object[o] * points[idx].p_in_object;
        if (p.z() < preset.min_depth_m || p.z() > preset.max_depth_m) continue;
        Eigen::Vector3d x;
        if (!cam.Project<double>(p, &x) || !cam.InImage(x)) continue;
        const double t_max_left = 1.0 - 1e-6 / p.norm();
        const double t_max_right = 1.0 - 1e-6 / (p - centre_right).norm();
        bool blocked = false;
        for (int other : grid_left.At(x(0), x(1)))
          if (Blocks(cam_quads[other], centre_left, p, t_max_left)) { blocked = true; break; }
        if (blocked) continue;
        for (int other : grid_right.At(x(2), x(1)))
          if (Blocks(cam_quads[other], centre_right, p, t_max_right)) { blocked = true; break; }
        if (blocked) continue;
        sightings[f].push_back({idx, -1, x});
      }
    }
  }

  // Tracklets: maximal runs of consecutive frames; a point seen again later starts a new one.
  struct Run {
    int point, start, length;
  };
  std::vector<Run> runs;
  std::vector<int> last_seen(points.size(), -2), open_run(points.size(), -1);
  for (int f = 0; f < frames; ++f) {
    for (Sighting& s : sightings[f]) {
      if (last_seen[s.point] != f - 1) {
        open_run[s.point] = static_cast<int>(runs.size());
        runs.push_back({s.point, f, 0});
      }
      s.run = open_run[s.point];
      ++runs[s.run].length;
      last_seen[s.point] = f;
    }
  }
  std::vector<int> order(runs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::tie(runs[a].start, runs[a].point) < std::tie(runs[b].start, runs[b].point);
  });
  std::vector<int> landmark_of_run(runs.size(), -1);
  for (int r : order) {
    if (runs[r].length < kMinTrackLength) continue;
    landmark_of_run[r] = static_cast<int>(seq.landmark_object.size());
    seq.landmark_object.push_back(points[runs[r].point].object);
    seq.landmark_in_object.push_back(points[runs[r].point].p_in_object);
  }

  // Noisy observations, frame by frame in landmark order (fixes the noise stream's order).
  const double a = options.noise_px;
  const double variance = std::max(options.gaussian_noise ? a * a : a * a / 3.0, 1e-12);
  const Eigen::Matrix3d cov = variance * Eigen::Matrix3d::Identity();
  for (int f = 0; f < frames; ++f) {
    std::vector<std::pair<int, Eigen::Vector3d>> obs;
    for (const Sighting& s : sightings[f])
      if (landmark_of_run[s.run] >= 0) obs.emplace_back(landmark_of_run[s.run], s.x);
    std::sort(obs.begin(), obs.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
    for (const auto& [landmark, exact] : obs) {
      Eigen::Vector3d x = exact;
      if (a > 0) {
        do {
          for (int i = 0; i < 3; ++i)
            x(i) = exact(i) + (options.gaussian_noise ? a * noise_rng.Normal() : noise_rng.Uniform(-a, a));
        } while (x(0) - x(2) < kMinNoisyDisparityPx);
      }
      seq.observations.Add(landmark, f, x, cov);
    }
  }
  // The table only knows frames up to the last observation; the ground truth has them all.
  if (seq.observations.num_frames() < frames)
    GetLogger("system")->warn("synthetic: the last frames of {} have no observations", seq.name);

  GetLogger("system")->debug("synthetic {}: {} frames, {} objects, {} surface points, {} landmarks, "
                             "{} observations in {:.2f} s",
                             seq.name, frames, objects, points.size(), seq.landmark_object.size(),
                             seq.observations.num_observations(), timer.ElapsedS());
  return seq;
}

}  // namespace cslam
