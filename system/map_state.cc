#include "system/map_state.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/logging.h"

namespace cslam {

void MapStateOptions::Check() const {
  CheckOption(association_overlap > 0 && association_overlap <= 1, "map.association_overlap",
              "must be in (0, 1]", association_overlap);
  CheckOption(min_shared_for_alignment >= 3, "map.min_shared_for_alignment",
              "must be at least 3 (a rigid alignment needs 3 points)", min_shared_for_alignment);
}

void MapStateOptions::Load(OptionsReader& r) {
  r.Read("association_overlap", &association_overlap);
  r.Read("min_shared_for_alignment", &min_shared_for_alignment);
  r.Finish();
}

MapState::MapState(MapStateOptions options) : options_(options) { options_.Check(); }

int MapState::ClusterOf(int landmark) const {
  const auto it = landmarks_.find(landmark);
  return it == landmarks_.end() ? -1 : it->second.cluster;
}

std::optional<Eigen::Vector3d> MapState::PositionInCluster(int landmark) const {
  const auto it = landmarks_.find(landmark);
  if (it == landmarks_.end()) return std::nullopt;
  return it->second.p_in_cluster;
}

std::optional<Eigen::Vector3d> MapState::WorldPosition(int landmark, int frame) const {
  const auto it = landmarks_.find(landmark);
  if (it == landmarks_.end()) return std::nullopt;
  if (it->second.cluster == 0) return it->second.p_in_cluster;
  const auto c = clusters_.find(it->second.cluster);
  if (c == clusters_.end()) return std::nullopt;
  const auto pose = c->second.world_from_cluster.find(frame);
  if (pose == c->second.world_from_cluster.end()) return std::nullopt;
  return pose->second * it->second.p_in_cluster;
}

std::vector<int> MapState::Landmarks() const {
  std::vector<int> ids;
  ids.reserve(landmarks_.size());
  for (const auto& [id, state] : landmarks_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

void MapState::SetCameraPose(int frame, const Pose& world_from_cam) {
  if (frame >= num_frames()) world_from_cam_.resize(frame + 1);
  world_from_cam_[frame] = world_from_cam;
}

WindowIntegration MapState::Integrate(const MotionEstimate& window) {
  WindowIntegration info;
  info.range = window.range;
  const int begin = window.range.begin;
  CSLAM_CHECK(static_cast<int>(window.world_from_cam.size()) == window.range.size(),
              "window estimate needs one camera pose per frame");

  // Chain the window to the newest map pose it shares: the window's own first frames were
  // estimated with less context than the map's older windows had.
  Pose map_from_window = Pose::Identity();
  for (int f = std::min(window.range.end, num_frames()) - 1; f >= begin; --f) {
    if (world_from_cam_[f]) {
      info.anchor_frame = f;
      map_from_window = *world_from_cam_[f] * window.world_from_cam[f - begin].inverse();
      break;
    }
  }
  if (info.anchor_frame < 0 && num_frames() > 0) {
    // No shared frame: continue from the last known pose as if the window started there.
    for (int f = num_frames() - 1; f >= 0; --f) {
      if (world_from_cam_[f]) {
        map_from_window = *world_from_cam_[f] * window.world_from_cam[0].inverse();
        break;
      }
    }
    info.gap = true;
    gaps_.push_back(begin);
    GetLogger("system")->warn("window {}..{} shares no frame with the map: trajectory gap", begin,
                              window.range.end - 1);
  }
  for (int f = begin; f < window.range.end; ++f) {
    if (f >= num_frames() || !world_from_cam_[f])
      SetCameraPose(f, map_from_window * window.world_from_cam[f - begin]);
  }

  // Group the window's landmarks by label.
  std::map<int, std::vector<int>> members;
  for (int l = 0; l < static_cast<int>(window.landmark_cluster.size()); ++l)
    if (window.landmark_cluster[l] >= 0 && window.landmark_in_cluster[l].allFinite())
      members[window.landmark_cluster[l]].push_back(l);

  auto assign = [&](int landmark, int cluster, const Eigen::Vector3d& p) {
    auto& state = landmarks_[landmark];
    if (state.cluster >= 1 && state.cluster != cluster) {
      auto it = clusters_.find(state.cluster);
      if (it != clusters_.end()) --it->second.num_landmarks;
    }
    if (cluster >= 1 && state.cluster != cluster) ++clusters_[cluster].num_landmarks;
    state.cluster = cluster;
    state.p_in_cluster = p;
  };

  if (auto it = members.find(0); it != members.end())
    for (int l : it->second) assign(l, 0, map_from_window * window.landmark_in_cluster[l]);

  // Candidate associations, strongest overlap first, one window cluster per map cluster.
  struct Candidate {
    int window_label, map_id, shared;
    double ratio;
  };
  std::vector<Candidate> candidates;
  for (const auto& [label, ids] : members) {
    if (label == 0) continue;
    std::map<int, int> shared;
    for (int l : ids) {
      const int c = ClusterOf(l);
      if (c >= 1) ++shared[c];
    }
    for (const auto& [map_id, count] : shared)
      candidates.push_back({label, map_id, count, double(count) / double(ids.size())});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.ratio != b.ratio ? a.ratio > b.ratio : a.window_label < b.window_label;
  });
  std::map<int, int> window_to_map;
  std::map<int, bool> map_taken;
  for (const auto& c : candidates) {
    if (c.ratio < options_.association_overlap) break;
    if (window_to_map.count(c.window_label) || map_taken[c.map_id]) continue;
    window_to_map[c.window_label] = c.map_id;
    map_taken[c.map_id] = true;
  }

  for (const auto& [label, ids] : members) {
    if (label == 0) continue;
    const ClusterMotion* motion = window.FindCluster(label);
    if (!motion || motion->frames.empty()) continue;
    // mapcluster_from_wincluster maps the window's cluster frame into the map's.
    Pose mapcluster_from_wincluster = Pose::Identity();
    int map_id = -1;
    if (auto it = window_to_map.find(label); it != window_to_map.end()) {
      std::vector<Eigen::Vector3d> src, dst;
      for (int l : ids) {
        if (ClusterOf(l) != it->second) continue;
        src.push_back(window.landmark_in_cluster[l]);
        dst.push_back(landmarks_[l].p_in_cluster);
      }
      const MapCluster& mc = clusters_[it->second];
      bool aligned = false;
      if (static_cast<int>(src.size()) >= options_.min_shared_for_alignment) {
        mapcluster_from_wincluster = AlignUmeyama(src, dst, false).rigid;
        aligned = true;
      } else {
        for (size_t k = motion->frames.size(); k-- > 0;) {
          const auto pose = mc.world_from_cluster.find(motion->frames[k]);
          if (pose == mc.world_from_cluster.end()) continue;
          mapcluster_from_wincluster =
              pose->second.inverse() * map_from_window * motion->world_from_cluster[k];
          aligned = true;
          break;
        }
      }
      if (aligned) {
        map_id = it->second;
        ++info.associated;
      }
    }
    if (map_id < 0) {
      map_id = next_cluster_id_++;
      clusters_[map_id].id = map_id;
      mapcluster_from_wincluster = Pose::Identity();
      ++info.created;
    }
    info.cluster_map.emplace_back(label, map_id);
    MapCluster& mc = clusters_[map_id];
    const Pose wincluster_from_mapcluster = mapcluster_from_wincluster.inverse();
    for (size_t k = 0; k < motion->frames.size(); ++k) {
      // Keep poses already in the map so the published trajectory never changes under a
      // reader's feet; the window only extends it.
      mc.world_from_cluster.try_emplace(
          motion->frames[k], map_from_window * motion->world_from_cluster[k] * wincluster_from_mapcluster);
    }
    for (int l : ids) assign(l, map_id, mapcluster_from_wincluster * window.landmark_in_cluster[l]);
  }
  return info;
}

}  // namespace cslam
