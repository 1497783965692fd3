#pragma once
// The pieces the synthetic scene builders share (system/synthetic/outdoor_scene.cc,
// indoor_scene.cc, synthetic_scene.cc): the seeded random streams, the presets' constants,
// pose and quad helpers, paths with rounded corners, and the draft a builder returns.
// Internal to the synthetic library.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "system/synthetic/scene_geometry.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam::synthetic_detail {

inline constexpr double kPi = std::numbers::pi;

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

inline constexpr Preset kOutdoor{10.0, 0.50, 1.0, 55.0, 200, 750, 5, 10, 0.16, 2.5, 0.6, 1.6};
inline constexpr Preset kIndoor{30.0, 0.10, 0.3, 8.0, 190, 300, 2, 5, 5.0, 40.0, 0.6, 1.6};

inline StereoCamera PaperCamera(double baseline) {
  StereoCamera cam;
  cam.fx = cam.fy = 640.0;  // 1280 px wide, horizontal FOV 90°
  cam.cx = 639.5;
  cam.cy = 359.5;
  cam.width = 1280;
  cam.height = 720;
  cam.baseline = baseline;
  return cam;
}

inline Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }
inline Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
inline Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }

inline Pose MakePose(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = r;
  p.translation() = t;
  return p;
}

/// Ground frame G (x east, y north, z up) pose of a camera at `position` looking along
/// `forward`, rolled by `roll` about the optical axis. Camera axes: x right, y down, z forward.
inline Pose CameraPose(const Eigen::Vector3d& position, const Eigen::Vector3d& forward, double roll) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r << x, y, z;
  return MakePose(r * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).matrix(), position);
}

/// True when a point (ground frame) is in the camera's field of view within a depth range.
inline bool InFrustum(const Pose& g_from_cam, const StereoCamera& cam, const Eigen::Vector3d& p_in_g,
               double min_depth, double max_depth) {
  const Eigen::Vector3d p = g_from_cam.inverse() * p_in_g;
  if (p.z() < min_depth || p.z() > max_depth) return false;
  return std::abs(p.x() / p.z()) < cam.cx / cam.fx && std::abs(p.y() / p.z()) < cam.cy / cam.fy;
}

/// Splits a rectangle into tiles no longer than `max_edge` metres (separate textures, so a
/// renderer's texture resolution stays reasonable on large surfaces).
inline void AddTiled(const SceneQuad& quad, double max_edge, std::vector<SceneQuad>* quads) {
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
inline SceneQuad GroundQuad(double x0, double x1, double y0, double y1, double z,
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

inline std::vector<double> Times(int frames, double rate) {
  std::vector<double> t(frames);
  for (int f = 0; f < frames; ++f) t[f] = f / rate;
  return t;
}

/// A car body in its own frame: x forward, y left, z up, origin on the ground at its centre.
inline SceneBody MakeCar(Rng& scene) {
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

/// What every builder draws first, in this order: the frame count and the object count
/// (both always drawn, so overriding one leaves the rest of the scene unchanged).
struct DraftStart {
  Draft draft;
  std::vector<double> t;  ///< time of each frame, s
  int objects = 0;        ///< moving objects to place
};
inline DraftStart StartDraft(const Preset& preset, const SyntheticOptions& options, Rng& scene) {
  DraftStart s;
  s.draft.rate_hz = preset.rate_hz;
  const int drawn_frames = scene.Int(preset.min_frames, preset.max_frames);
  const int drawn_objects = scene.Int(preset.min_objects, preset.max_objects);
  s.t = Times(options.frames > 0 ? options.frames : drawn_frames, preset.rate_hz);
  s.objects = options.objects >= 0 ? options.objects : drawn_objects;
  return s;
}

/// The street scene with a junction: buildings, parked and moving cars, a camera car.
Draft BuildOutdoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj);
/// The furnished room: walls, furniture, moving boxes, a hand-held camera.
Draft BuildIndoor(const SyntheticOptions& options, const StereoCamera& cam, Rng& scene, Rng& traj);

}  // namespace cslam::synthetic_detail
