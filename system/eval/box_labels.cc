#include "system/eval/box_labels.h"

#include <algorithm>
#include <map>

namespace cslam {

namespace {

// KITTI boxes: origin at the bottom-face centre, x along the length, y along the width,
// z up (velodyne convention); cam_from_box maps box points into the camera frame.
bool InsideBox(const ObjectBox& box, const Eigen::Vector3d& p_in_cam, double margin) {
  const Eigen::Vector3d p = box.cam_from_box.inverse() * p_in_cam;
  return std::abs(p.x()) <= box.l / 2 + margin && std::abs(p.y()) <= box.w / 2 + margin &&
         p.z() >= -margin && p.z() <= box.h + margin;
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
  std::vector<int> labels(table.num_landmarks(), 0);
  for (int l = 0; l < table.num_landmarks(); ++l) {
    const auto obs = table.ObservationsOf(l);
    if (obs.empty()) continue;
    std::vector<int> votes(moving_tracks.size(), 0);
    for (const StereoObservation& o : obs) {
      if (o.frame >= static_cast<int>(boxes.size())) continue;
      Eigen::Vector3d p;
      if (!camera.BackProject(o.x, &p)) continue;
      for (const ObjectBox& box : boxes[o.frame]) {
        const auto it = std::find(moving_tracks.begin(), moving_tracks.end(), box.track_id);
        if (it == moving_tracks.end()) continue;
        if (InsideBox(box, p, options.margin_m)) ++votes[it - moving_tracks.begin()];
      }
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
