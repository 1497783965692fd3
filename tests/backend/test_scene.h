#pragma once
// Small ground-truth scenes for the backend tests: rigid point sets with known motions seen by
// a known stereo camera with known pixel noise.
#include <Eigen/Geometry>
#include <functional>
#include <random>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "tests/support/random.h"

namespace cslam::testing {

/// 1280×720, fx = 640 (HFOV 90°); baseline 0.10 m indoor, 0.50 m outdoor (spec §10).
inline StereoCamera SyntheticCamera(bool outdoor) {
  StereoCamera cam;
  cam.fx = cam.fy = 640.0;
  cam.cx = 640.0;
  cam.cy = 360.0;
  cam.width = 1280;
  cam.height = 720;
  cam.baseline = outdoor ? 0.5 : 0.1;
  return cam;
}

/// A rigid point set and its pose per frame.
struct TestBody {
  std::vector<Eigen::Vector3d> points_in_body;
  std::function<Pose(int)> world_from_body;
};

/// Observations with their truth: landmark ids are assigned body by body, in order.
struct TestScene {
  StereoCamera camera;
  TrackletTable table;
  std::vector<int> truth;  ///< [landmark] body index (0 = the first body)
  std::vector<Pose> world_from_cam;
};

/// `noise_px` is the true standard deviation added to (uL, vL, uR); the observation covariance
/// is `cov_sigma_px`² I (the frontend's nominal model).
inline TestScene MakeScene(const StereoCamera& camera, const std::vector<TestBody>& bodies,
                           int num_frames, const std::function<Pose(int)>& world_from_cam,
                           double noise_px, double cov_sigma_px, unsigned seed) {
  TestScene s;
  s.camera = camera;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int t = 0; t < num_frames; ++t) s.world_from_cam.push_back(world_from_cam(t));
  const Eigen::Matrix3d cov = cov_sigma_px * cov_sigma_px * Eigen::Matrix3d::Identity();
  int id = 0;
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (const auto& p : bodies[b].points_in_body) {
      for (int t = 0; t < num_frames; ++t) {
        const Eigen::Vector3d p_cam =
            s.world_from_cam[t].inverse() * (bodies[b].world_from_body(t) * p);
        Eigen::Vector3d x;
        if (!camera.Project(p_cam, &x, 0.5) || !camera.InImage(x)) continue;
        if (noise_px > 0)
          for (int k = 0; k < 3; ++k) x(k) += noise_px * noise(rng);
        if (x(0) - x(2) <= 0.05) continue;
        s.table.Add(id, t, x, cov);
      }
      s.truth.push_back(static_cast<int>(b));
      ++id;
    }
  }
  return s;
}

/// `n` points uniform in the box [lo, hi].
inline std::vector<Eigen::Vector3d> RandomPoints(int n, const Eigen::Vector3d& lo,
                                                 const Eigen::Vector3d& hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i)
    out.push_back(lo + testing::Draw3([&] { return u(rng); }).cwiseProduct(hi - lo));
  return out;
}

/// Pose with rotation about y by `yaw` rad and translation t.
inline Pose YawPose(double yaw, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  p.translation() = t;
  return p;
}

/// Fraction of landmarks whose label matches the truth under the best one-to-one matching of
/// labels (brute force over the contingency table: fine for a handful of clusters).
/// Landmarks labelled -1 count as errors.
inline double ClusteringAccuracy(const std::vector<int>& labels, const std::vector<int>& truth) {
  int num_pred = 0, num_true = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    num_true = std::max(num_true, truth[i] + 1);
    if (i < labels.size()) num_pred = std::max(num_pred, labels[i] + 1);
  }
  std::vector<std::vector<int>> count(num_true, std::vector<int>(num_pred, 0));
  for (size_t i = 0; i < truth.size(); ++i)
    if (i < labels.size() && labels[i] >= 0) ++count[truth[i]][labels[i]];
  // Best matching by recursion over truth labels (few clusters in tests).
  std::vector<char> used(num_pred, 0);
  std::function<int(int)> best = [&](int t) -> int {
    if (t == num_true) return 0;
    int b = best(t + 1);  // truth label t unmatched
    for (int p = 0; p < num_pred; ++p) {
      if (used[p]) continue;
      used[p] = 1;
      b = std::max(b, count[t][p] + best(t + 1));
      used[p] = 0;
    }
    return b;
  };
  return truth.empty() ? 1.0 : static_cast<double>(best(0)) / truth.size();
}

}  // namespace cslam::testing
