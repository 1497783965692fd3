#pragma once
// A small self-contained multi-body stereo scene for backend tests: rigid point sets with known
// trajectories projected through a StereoCamera with known pixel noise. (The library generator
// system/synthetic/synthetic_scene.h is richer; this one only needs what the backend tests pin.)
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "tests/support/random.h"

namespace cslam::testing {

/// What to generate.
struct BodySceneSpec {
  int num_frames = 30;
  bool outdoor = false;  ///< baseline 0.5 m, far points, fast camera
  int num_static = 300;
  int num_moving = 2;  ///< moving rigid bodies
  int points_per_body = 60;
  double pixel_sigma = 1.0;             ///< px, on uL, vL, uR
  double gross_outlier_fraction = 0.0;  ///< observations displaced by `gross_outlier_px`
  double gross_outlier_px = 40.0;
  unsigned seed = 1;
};

/// Ground truth and observations.
struct BodyScene {
  StereoCamera camera;
  TrackletTable table;
  std::vector<Pose> world_from_cam;                ///< [frame]; world = camera at frame 0
  std::vector<std::vector<Pose>> world_from_body;  ///< [body][frame]; body 0 = static (I)
  std::vector<int> labels;                         ///< [landmark] body index
  std::vector<Eigen::Vector3d> point_in_body;      ///< [landmark]
};

inline Pose MakePose(double yaw, double pitch, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  p.translation() = t;
  return p;
}

inline BodyScene MakeBodyScene(const BodySceneSpec& spec) {
  BodyScene s;
  s.camera.fx = s.camera.fy = 640;
  s.camera.cx = 640;
  s.camera.cy = 360;
  s.camera.width = 1280;
  s.camera.height = 720;
  s.camera.baseline = spec.outdoor ? 0.5 : 0.1;
  const double speed = spec.outdoor ? 1.0 : 0.05;  // m per frame along z
  const double far = spec.outdoor ? 60.0 : 10.0;
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uni = [&](double a, double b) { return a + (b - a) * u01(rng); };
  // A point uniform in the box [lo, hi], drawn in a compiler-independent order (random.h).
  auto uni3 = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) -> Eigen::Vector3d {
    return lo + (hi - lo).cwiseProduct(testing::Draw3([&] { return u01(rng); }));
  };

  const Pose cam0 = MakePose(0.0, 0.0, Eigen::Vector3d::Zero());
  for (int t = 0; t < spec.num_frames; ++t) {
    const Pose p = MakePose(0.08 * std::sin(t / 8.0), 0.02 * std::sin(t / 5.0),
                            Eigen::Vector3d(0.3 * speed * std::sin(t / 6.0),
                                            0.05 * speed * std::sin(t / 4.0), speed * t));
    s.world_from_cam.push_back(cam0.inverse() * p);
  }
  const double travel = speed * spec.num_frames;
  s.world_from_body.push_back(std::vector<Pose>(spec.num_frames, Pose::Identity()));
  for (int i = 0; i < spec.num_static; ++i) {
    s.labels.push_back(0);
    if (spec.outdoor)
      s.point_in_body.push_back(uni3({-25, -4, 6}, {25, 2, far + travel}));
    else
      s.point_in_body.push_back(uni3({-4, -2, 2.5}, {4, 2, far + travel}));
  }
  for (int b = 1; b <= spec.num_moving; ++b) {
    const double side = (b % 2 == 1) ? 1.0 : -1.0;
    const Eigen::Vector3d start = spec.outdoor ? Eigen::Vector3d(side * 4.0, 0.5, 12.0 + 4 * b)
                                               : Eigen::Vector3d(side * 0.9, 0.2, 2.4 + 0.4 * b);
    const Eigen::Vector3d vel = spec.outdoor
                                    ? Eigen::Vector3d(-side * 0.08, 0.0, speed + 0.4 * b)
                                    : Eigen::Vector3d(-side * 0.02, 0.005 * b, speed + 0.015 * b);
    const double spin = 0.015 * b * side;
    std::vector<Pose> traj;
    for (int t = 0; t < spec.num_frames; ++t)
      traj.push_back(MakePose(0.3 * b + spin * t, 0.0, start + vel * t));
    s.world_from_body.push_back(traj);
    const Eigen::Vector3d half =
        spec.outdoor ? Eigen::Vector3d(1.0, 0.8, 2.2) : Eigen::Vector3d(0.5, 0.4, 0.5);
    for (int i = 0; i < spec.points_per_body; ++i) {
      s.labels.push_back(b);
      s.point_in_body.push_back(uni3(-half, half));
    }
  }

  std::normal_distribution<double> noise(0.0, spec.pixel_sigma);
  const Eigen::Matrix3d cov = spec.pixel_sigma * spec.pixel_sigma * Eigen::Matrix3d::Identity();
  for (int i = 0; i < static_cast<int>(s.labels.size()); ++i) {
    const int id = s.table.NewLandmark();
    for (int t = 0; t < spec.num_frames; ++t) {
      const Eigen::Vector3d p_cam =
          s.world_from_cam[t].inverse() * (s.world_from_body[s.labels[i]][t] * s.point_in_body[i]);
      if (p_cam.z() < 1.0 || p_cam.z() > far) continue;
      Eigen::Vector3d x;
      if (!s.camera.Project(p_cam, &x) || !s.camera.InImage(x, 2.0)) continue;
      x += testing::Draw3([&] { return noise(rng); });
      if (u01(rng) < spec.gross_outlier_fraction) {
        const double shift_y = uni(-1, 1), shift_x = uni(-1, 1);  // gcc's order (random.h)
        const Eigen::Vector2d shift(shift_x, shift_y);
        const Eigen::Vector2d off = shift.normalized() * spec.gross_outlier_px;
        x += Eigen::Vector3d(off.x(), off.y(), off.x());
      }
      if (x(0) - x(2) < 0.5) continue;  // the frontend would not match a non-positive disparity
      s.table.Add(id, t, x, cov);
    }
  }
  return s;
}

/// RMSE of the translational error after SE(3) Umeyama alignment (spec §9 ATE).
inline double Ate(const std::vector<Pose>& estimate, const std::vector<Pose>& truth) {
  std::vector<Eigen::Vector3d> a, b;
  for (size_t k = 0; k < estimate.size(); ++k) {
    a.push_back(estimate[k].translation());
    b.push_back(truth[k].translation());
  }
  const Sim3 align = AlignUmeyama(a, b, false);
  double sum = 0.0;
  for (size_t k = 0; k < a.size(); ++k) sum += (align.Apply(a[k]) - b[k]).squaredNorm();
  return std::sqrt(sum / std::max<size_t>(a.size(), 1));
}

/// Centroids of the landmarks that cluster `label` of `est` shares with true body `body`: in
/// the cluster's frame (the estimate's positions) and in the body's (the truth's); n of them.
struct SharedCentroids {
  Eigen::Vector3d in_cluster = Eigen::Vector3d::Zero(), in_body = Eigen::Vector3d::Zero();
  int n = 0;
};

template <typename Estimate>
SharedCentroids CentroidsOf(const BodyScene& scene, const Estimate& est, int label, int body) {
  SharedCentroids c;
  for (size_t i = 0; i < est.landmark_cluster.size(); ++i)
    if (est.landmark_cluster[i] == label && scene.labels[i] == body) {
      c.in_cluster += est.landmark_in_cluster[i];
      c.in_body += scene.point_in_body[i];
      ++c.n;
    }
  if (c.n > 0) {
    c.in_cluster /= c.n;
    c.in_body /= c.n;
  }
  return c;
}

/// Error of a moving cluster's estimated track: the centroid of its landmarks, moved by
/// world_from_cluster, against the true centroid moved by world_from_body, as an RMSE over
/// its frames. The centroid (not the cluster frame's origin, which is the camera at first
/// sight, metres away) keeps rotation errors from being amplified by an arbitrary lever arm.
template <typename Estimate>
double CentroidTrackRmse(const BodyScene& scene, const Estimate& est, int label) {
  const auto* m = est.FindCluster(label);
  if (!m) return std::numeric_limits<double>::infinity();
  const SharedCentroids c = CentroidsOf(scene, est, label, label);
  double sum = 0.0;
  for (size_t k = 0; k < m->frames.size(); ++k)
    sum += (m->world_from_cluster[k] * c.in_cluster -
            scene.world_from_body[label][m->frames[k]] * c.in_body)
               .squaredNorm();
  return std::sqrt(sum / m->frames.size());
}

/// The same centroid's step from each frame to the next, against the truth's, as an RMSE over
/// the consecutive frame pairs: what RPE per frame measures for an object.
template <typename Estimate>
double CentroidStepError(const BodyScene& scene, const Estimate& est, int label, int body) {
  const auto* m = est.FindCluster(label);
  const SharedCentroids c = CentroidsOf(scene, est, label, body);
  if (!m || c.n == 0) return std::numeric_limits<double>::infinity();
  const auto& truth = scene.world_from_body[body];
  double sum = 0.0;
  int steps = 0;
  for (size_t k = 0; k + 1 < m->frames.size(); ++k) {
    const int f = m->frames[k], g = m->frames[k + 1];
    if (g != f + 1) continue;
    const Eigen::Vector3d step = m->world_from_cluster[k + 1] * c.in_cluster - m->world_from_cluster[k] * c.in_cluster;
    sum += (step - (truth[g] * c.in_body - truth[f] * c.in_body)).squaredNorm();
    ++steps;
  }
  return std::sqrt(sum / std::max(steps, 1));
}

/// The centroid's error about its mean over the frames (RMS): the track's scatter without the
/// constant offset a few points' centroid carries, which no motion prior can see.
template <typename Estimate>
double CentroidTrackScatter(const BodyScene& scene, const Estimate& est, int label) {
  const auto* m = est.FindCluster(label);
  const SharedCentroids c = CentroidsOf(scene, est, label, label);
  if (!m || c.n == 0) return std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> d;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < m->frames.size(); ++k) {
    d.push_back(m->world_from_cluster[k] * c.in_cluster -
                scene.world_from_body[label][m->frames[k]] * c.in_body);
    mean += d.back();
  }
  mean /= d.size();
  double sum = 0.0;
  for (const Eigen::Vector3d& e : d) sum += (e - mean).squaredNorm();
  return std::sqrt(sum / d.size());
}

/// Mean rotation error (rad) after aligning the first poses (both trajectories start at I).
inline double MeanRotationError(const std::vector<Pose>& estimate, const std::vector<Pose>& truth) {
  double sum = 0.0;
  for (size_t k = 0; k < estimate.size(); ++k)
    sum += RotationAngle(estimate[k].linear().transpose() * truth[k].linear());
  return sum / std::max<size_t>(estimate.size(), 1);
}

}  // namespace cslam::testing
