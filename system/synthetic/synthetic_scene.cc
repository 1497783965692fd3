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
#include "system/synthetic/scene_draft.h"

namespace cslam {

using namespace synthetic_detail;

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
  CheckOption(baseline_m == 0.0 || (baseline_m >= 0.01 && baseline_m <= 2.0), "baseline_m",
              "must be 0 (the preset's) or in [0.01, 2] m", baseline_m);
}

void SyntheticOptions::Load(OptionsReader& reader) {
  reader.Read("preset", &preset);
  reader.Read("seed", &seed);
  reader.Read("frames", &frames);
  reader.Read("objects", &objects);
  reader.Read("noise_px", &noise_px);
  reader.Read("gaussian_noise", &gaussian_noise);
  reader.Read("landmark_density", &landmark_density);
  reader.Read("baseline_m", &baseline_m);
}

double SyntheticSequence::CameraTravel() const {
  double travel = 0.0;
  for (size_t f = 1; f < world_from_cam.size(); ++f)
    travel += (world_from_cam[f].translation() - world_from_cam[f - 1].translation()).norm();
  return travel;
}

namespace {

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
  seq.camera = PaperCamera(options.baseline_m > 0 ? options.baseline_m : preset.baseline_m);
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
