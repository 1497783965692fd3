#include "system/eval/box_labels.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace cslam {

namespace {

// KITTI boxes: origin at the bottom-face centre, x along the length, y along the width,
// z up (velodyne convention); cam_from_box maps box points into the camera frame.
// A box as the camera sees it: its outline in the image (convex, counter-clockwise) and the
// depth range of its corners.
struct BoxInImage {
  std::vector<Eigen::Vector2d> outline;
  double z_min = 0, z_max = 0;
};

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// Andrew's monotone chain; false when a corner is not in front of the camera.
bool ProjectBox(const ObjectBox& box, const StereoCamera& camera, BoxInImage* out) {
  std::vector<Eigen::Vector2d> pts;
  out->z_min = INFINITY;
  out->z_max = -INFINITY;
  for (double x : {-box.l / 2, box.l / 2})
    for (double y : {-box.w / 2, box.w / 2})
      for (double z : {0.0, box.h}) {
        const Eigen::Vector3d c = box.cam_from_box * Eigen::Vector3d(x, y, z);
        Eigen::Vector3d uvr;
        if (!camera.Project(c, &uvr, 0.1)) return false;
        pts.emplace_back(uvr.x(), uvr.y());
        out->z_min = std::min(out->z_min, c.z());
        out->z_max = std::max(out->z_max, c.z());
      }
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k > 0 ? k - 1 : 0);
  out->outline = hull;
  return hull.size() >= 3;
}

// Inside the outline or within `tolerance` pixels of it.
bool InsideOutline(const std::vector<Eigen::Vector2d>& outline, const Eigen::Vector2d& p,
                   double tolerance) {
  for (size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % outline.size()];
    if (Cross(a, b, p) < -tolerance * (b - a).norm()) return false;
  }
  return true;
}

// The observation lies on the box: its keypoint inside the outline and its depth within the
// box's depth range, each up to `sigmas` of its own standard deviation.
bool OnBox(const BoxInImage& box, const StereoObservation& o, const StereoCamera& camera,
           double sigmas) {
  const double sigma_px = std::sqrt(std::max(o.cov(0, 0), o.cov(1, 1)));
  if (!InsideOutline(box.outline, Eigen::Vector2d(o.x(0), o.x(1)), sigmas * sigma_px)) return false;
  const double d = o.x(0) - o.x(2);
  if (!(d > 0)) return false;
  const double fb = camera.fx * camera.baseline;
  const double z = fb / d;
  const double var_d = o.cov(0, 0) + o.cov(2, 2) - 2 * o.cov(0, 2);
  const double sigma_z = z * z / fb * std::sqrt(std::max(var_d, 0.0));
  return z >= box.z_min - sigmas * sigma_z && z <= box.z_max + sigmas * sigma_z;
}

Eigen::Vector3d BoxCentreInCam(const ObjectBox& box) {
  return box.cam_from_box * Eigen::Vector3d(0, 0, box.h / 2);
}

}  // namespace

std::vector<int> MovingTrackIds(const std::vector<std::vector<ObjectBox>>& boxes,
                                const std::vector<Pose>& world_from_cam,
                                const BoxLabelOptions& options) {
  std::map<int, std::pair<Eigen::Vector3d, double>> first_and_max;  // id → (first pos, max dist)
  const size_t n = std::min(boxes.size(), world_from_cam.size());
  for (size_t f = 0; f < n; ++f) {
    for (const ObjectBox& box : boxes[f]) {
      const Eigen::Vector3d p = world_from_cam[f] * BoxCentreInCam(box);
      auto it = first_and_max.find(box.track_id);
      if (it == first_and_max.end()) {
        first_and_max[box.track_id] = {p, 0.0};
      } else {
        it->second.second = std::max(it->second.second, (p - it->second.first).norm());
      }
    }
  }
  std::vector<int> moving;
  for (const auto& [id, v] : first_and_max)
    if (v.second >= options.min_travel_m) moving.push_back(id);
  return moving;
}

std::vector<int> LabelLandmarksByBoxes(const TrackletTable& table, const StereoCamera& camera,
                                       const std::vector<std::vector<ObjectBox>>& boxes,
                                       const std::vector<int>& moving_tracks,
                                       const BoxLabelOptions& options) {
  // The moving boxes of each frame as the camera sees them, projected once.
  std::vector<std::vector<std::pair<int, BoxInImage>>> seen(boxes.size());
  for (size_t f = 0; f < boxes.size(); ++f)
    for (const ObjectBox& box : boxes[f]) {
      const auto it = std::find(moving_tracks.begin(), moving_tracks.end(), box.track_id);
      BoxInImage b;
      if (it != moving_tracks.end() && ProjectBox(box, camera, &b))
        seen[f].emplace_back(static_cast<int>(it - moving_tracks.begin()), std::move(b));
    }
  std::vector<int> labels(table.num_landmarks(), 0);
  for (int l = 0; l < table.num_landmarks(); ++l) {
    const auto obs = table.ObservationsOf(l);
    if (obs.empty()) continue;
    std::vector<int> votes(moving_tracks.size(), 0);
    for (const StereoObservation& o : obs) {
      if (o.frame >= static_cast<int>(seen.size())) continue;
      for (const auto& [index, box] : seen[o.frame])
        if (OnBox(box, o, camera, options.depth_sigmas)) ++votes[index];
    }
    const auto best = std::max_element(votes.begin(), votes.end());
    if (best != votes.end() && *best >= options.min_inside_fraction * double(obs.size()) && *best > 0)
      labels[l] = 1 + static_cast<int>(best - votes.begin());
  }
  return labels;
}

std::vector<std::pair<int, Eigen::Vector3d>> BoxCentreTrajectory(
    const std::vector<std::vector<ObjectBox>>& boxes, const std::vector<Pose>& world_from_cam,
    int track_id) {
  std::vector<std::pair<int, Eigen::Vector3d>> out;
  const size_t n = std::min(boxes.size(), world_from_cam.size());
  for (size_t f = 0; f < n; ++f)
    for (const ObjectBox& box : boxes[f])
      if (box.track_id == track_id)
        out.emplace_back(static_cast<int>(f), world_from_cam[f] * BoxCentreInCam(box));
  return out;
}

}  // namespace cslam
