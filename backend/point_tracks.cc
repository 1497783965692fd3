#include "backend/point_tracks.h"

#include <algorithm>
#include <cmath>

namespace cslam {
namespace {

// Camera-from-cluster pose at `frame` for a landmark of `label`, or false when unknown.
bool CamFromCluster(const MotionEstimate& est, int label, int frame, Pose* cam_from_cluster) {
  if (label == 0) {
    const int k = frame - est.range.begin;
    if (k < 0 || k >= static_cast<int>(est.world_from_cam.size())) return false;
    *cam_from_cluster = est.world_from_cam[k].inverse();
    return true;
  }
  for (const ClusterMotion& c : est.clusters) {
    if (c.cluster != label) continue;
    auto it = std::lower_bound(c.frames.begin(), c.frames.end(), frame);
    if (it == c.frames.end() || *it != frame) return false;
    *cam_from_cluster = c.cam_from_cluster[it - c.frames.begin()];
    return true;
  }
  return false;
}

}  // namespace

std::optional<PointSample> BackProjectObservation(const StereoObservation& o,
                                                  const StereoCamera& camera) {
  PointSample s;
  s.frame = o.frame;
  Eigen::Matrix3d jac;
  if (!camera.BackProject<double>(o.x, &s.point, &jac)) return std::nullopt;
  s.cov = jac * o.cov * jac.transpose();
  s.disparity_px = o.x(0) - o.x(2);
  s.metres_per_px = s.point.z() / camera.fx;
  s.clipped = o.clipped;
  return s;
}

PointTracks BackProjectTracks(const TrackletTable& table, const StereoCamera& camera,
                              FrameRange range) {
  PointTracks tracks(table.num_landmarks());
  for (int l : table.LandmarksIn(range)) {
    for (const StereoObservation& o : table.ObservationsOf(l, range))
      if (const auto s = BackProjectObservation(o, camera)) tracks[l].samples.push_back(*s);
  }
  return tracks;
}

PointTracks RefineTracks(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                         const MotionEstimate& estimate, int half_window) {
  PointTracks tracks = BackProjectTracks(table, camera, range);
  if (half_window <= 0) return tracks;
  const int num_labelled = static_cast<int>(estimate.landmark_cluster.size());
  std::vector<Eigen::Vector3d> residual;
  std::vector<char> has_model;
  for (int l = 0; l < static_cast<int>(tracks.size()) && l < num_labelled; ++l) {
    const int label = estimate.landmark_cluster[l];
    auto& samples = tracks[l].samples;
    if (label < 0 || samples.empty() || l >= static_cast<int>(estimate.landmark_in_cluster.size()))
      continue;
    const Eigen::Vector3d& p_in_cluster = estimate.landmark_in_cluster[l];
    if (!p_in_cluster.allFinite()) continue;
    const size_t n = samples.size();
    residual.assign(n, Eigen::Vector3d::Zero());
    has_model.assign(n, 0);
    std::vector<Eigen::Vector3d> predicted(n);
    for (size_t k = 0; k < n; ++k) {
      Pose cam_from_cluster;
      if (!CamFromCluster(estimate, label, samples[k].frame, &cam_from_cluster)) continue;
      predicted[k] = cam_from_cluster * p_in_cluster;
      residual[k] = samples[k].point - predicted[k];
      has_model[k] = 1;
    }
    // Windowed mean of residuals and covariances over the landmark's own modelled samples.
    std::vector<PointSample> out = samples;
    for (size_t k = 0; k < n; ++k) {
      if (!has_model[k]) continue;
      Eigen::Vector3d r_sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d c_sum = Eigen::Matrix3d::Zero();
      int count = 0;
      for (size_t m = k; m-- > 0 && samples[m].frame >= samples[k].frame - half_window;)
        if (has_model[m]) r_sum += residual[m], c_sum += samples[m].cov, ++count;
      for (size_t m = k; m < n && samples[m].frame <= samples[k].frame + half_window; ++m)
        if (has_model[m]) r_sum += residual[m], c_sum += samples[m].cov, ++count;
      out[k].point = predicted[k] + r_sum / count;
      out[k].cov = c_sum / (static_cast<double>(count) * count);
    }
    samples = std::move(out);
  }
  return tracks;
}

}  // namespace cslam
