#include "system/map/map_state.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "backend/place_split.h"
#include "core/errors.h"
#include "core/logging.h"
#include "system/map/co_location.h"
#include "system/map/motion_agreement.h"
#include "system/map/reappearance.h"

namespace cslam {

void MapStateOptions::Check() const {
  CheckOption(association_overlap > 0 && association_overlap <= 1, "association_overlap",
              "must be in (0, 1]", association_overlap);
  CheckOption(min_shared_for_alignment >= 3, "min_shared_for_alignment",
              "must be at least 3 (a rigid alignment needs 3 points)", min_shared_for_alignment);
  CheckOption(known_overlap > 0 && known_overlap <= 1, "known_overlap", "must be in (0, 1]",
              known_overlap);
  CheckOption(containment_overlap > 0 && containment_overlap <= 1, "containment_overlap",
              "must be in (0, 1]", containment_overlap);
  CheckOption(motion_min_frames >= 2, "motion_min_frames",
              "must be at least 2 (one frame cannot show a motion)", motion_min_frames);
  CheckOption(motion_tolerance > 0, "motion_tolerance",
              "must be positive (RMS misplacement / mean range to the camera)", motion_tolerance);
  CheckOption(std::isfinite(co_location_ratio) && co_location_ratio >= 0, "co_location_ratio",
              "must be >= 0 (centroid distance / the smaller RMS radius; 0: off)",
              co_location_ratio);
  CheckOption(co_location_min_frames >= 1, "co_location_min_frames",
              "must be at least 1 (shared frames)", co_location_min_frames);
  CheckOption(merge_max_frames == 0 || merge_max_frames >= motion_min_frames, "merge_max_frames",
              "must be 0 (every shared frame) or at least motion_min_frames", merge_max_frames);
  CheckOption(merge_horizon_frames >= 0, "merge_horizon_frames", "must be >= 0 (0: all frames)",
              merge_horizon_frames);
  CheckOption(min_new_cluster_landmarks >= 1, "min_new_cluster_landmarks",
              "must be at least 1", min_new_cluster_landmarks);
  CheckOption(report_min_landmarks >= 1, "report_min_landmarks", "must be at least 1",
              report_min_landmarks);
  CheckOption(report_min_frames >= 1, "report_min_frames", "must be at least 1",
              report_min_frames);
  CheckOption(report_min_windows >= 1, "report_min_windows", "must be at least 1",
              report_min_windows);
  CheckOption(retire_after_frames >= 0, "retire_after_frames", "must be >= 0 (0: never)",
              retire_after_frames);
  CheckOption(std::isfinite(reappearance_max_gap_s) && reappearance_max_gap_s >= 0,
              "reappearance_max_gap_s", "must be >= 0 (seconds; 0: off)", reappearance_max_gap_s);
  CheckOption(std::isfinite(reappearance_max_acceleration_mps2) &&
                  reappearance_max_acceleration_mps2 >= 0,
              "reappearance_max_acceleration_mps2", "must be >= 0 (m/s²)",
              reappearance_max_acceleration_mps2);
  CheckOption(frame_period_s > 0 && std::isfinite(frame_period_s), "frame_period_s",
              "must be positive (seconds between frames)", frame_period_s);
  CheckOption(refine_camera_from >= 0, "refine_camera_from", "must be >= 0 (0: off)",
              refine_camera_from);
  CheckSection("track", [&] { track.Check(); });
}

void MapStateOptions::Load(OptionsReader& r) {
  r.Read("association_overlap", &association_overlap);
  r.Read("min_shared_for_alignment", &min_shared_for_alignment);
  r.Read("known_overlap", &known_overlap);
  r.Read("containment_overlap", &containment_overlap);
  r.Read("motion_association", &motion_association);
  r.Read("motion_min_frames", &motion_min_frames);
  r.Read("motion_tolerance", &motion_tolerance);
  r.Read("co_location_ratio", &co_location_ratio);
  r.Read("co_location_min_frames", &co_location_min_frames);
  r.Read("merge_horizon_frames", &merge_horizon_frames);
  r.Read("merge_max_frames", &merge_max_frames);
  r.Read("merge_agreeing_clusters", &merge_agreeing_clusters);
  r.Read("min_new_cluster_landmarks", &min_new_cluster_landmarks);
  r.Read("stitch_by_motion", &stitch_by_motion);
  r.Read("refine_camera_from", &refine_camera_from);
  r.Read("report_min_landmarks", &report_min_landmarks);
  r.Read("report_min_frames", &report_min_frames);
  r.Read("report_min_windows", &report_min_windows);
  r.Read("retire_after_frames", &retire_after_frames);
  r.Read("reappearance_max_gap_s", &reappearance_max_gap_s);
  r.Read("keep_lost_members", &keep_lost_members);
  r.Read("reappearance_max_acceleration_mps2", &reappearance_max_acceleration_mps2);
  r.ReadSection("track", &track);
}

MapState::MapState(MapStateOptions options) : options_(options) { options_.Check(); }

const MapState::LandmarkState* MapState::Find(int landmark) const {
  if (const auto it = landmarks_.find(landmark); it != landmarks_.end()) return &it->second;
  return retired_.Find(landmark);
}

int MapState::ClusterOf(int landmark) const {
  const LandmarkState* state = Find(landmark);
  return state ? state->cluster : -1;
}

std::optional<Eigen::Vector3d> MapState::PositionInCluster(int landmark) const {
  const LandmarkState* state = Find(landmark);
  if (!state) return std::nullopt;
  return state->p_in_cluster;
}

std::optional<Eigen::Vector3d> MapState::WorldPosition(int landmark, int frame) const {
  const LandmarkState* state = Find(landmark);
  if (!state) return std::nullopt;
  if (state->cluster <= 0) return state->p_in_cluster;
  const auto c = clusters_.find(state->cluster);
  if (c == clusters_.end()) return std::nullopt;
  const auto pose = c->second.world_from_cluster.find(frame);
  if (pose == c->second.world_from_cluster.end()) return std::nullopt;
  return pose->second * state->p_in_cluster;
}

std::vector<int> MapState::Landmarks() const {
  std::vector<int> ids;
  ids.reserve(landmarks_.size() + retired_.size());
  for (const auto& [id, state] : landmarks_) ids.push_back(id);
  retired_.ForEach([&](int id, const LandmarkState&) { ids.push_back(id); });
  std::sort(ids.begin(), ids.end());
  return ids;
}

int MapState::NumLiveClusters() const {
  std::set<int> live;
  for (const auto& [id, state] : landmarks_)
    if (state.cluster >= 1) live.insert(state.cluster);
  return static_cast<int>(live.size());
}

int MapState::WindowsCovering(int first, int last) const {
  // A window that ends by `first` also begins before `last`: the two counts nest.
  const auto begun = std::upper_bound(window_begins_.begin(), window_begins_.end(), last) -
                     window_begins_.begin();
  const auto ended = std::upper_bound(window_ends_.begin(), window_ends_.end(), first) -
                     window_ends_.begin();
  return static_cast<int>(begun - ended);
}

void MapState::RetireBefore(int frame) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    if (it->second.last_frame >= frame) {
      ++it;
      continue;
    }
    if (it->second.cluster >= 1) retired_by_cluster_[it->second.cluster].push_back(it->first);
    retired_.Put(it->first, it->second);
    it = landmarks_.erase(it);
  }
}

void MapState::RetiredStates::Put(int id, const LandmarkState& state) {
  if (id >= static_cast<int>(present_.size())) {
    present_.resize(static_cast<size_t>(id) + 1, 0);
    states_.resize(static_cast<size_t>(id) + 1);
  }
  if (!present_[id]) ++count_;
  present_[id] = 1;
  states_[id] = state;
}

void MapState::RetiredStates::Erase(int id) {
  if (id < 0 || id >= static_cast<int>(present_.size()) || !present_[id]) return;
  present_[id] = 0;
  --count_;
}

void MapState::ReleaseCluster(int id) {
  const auto c = clusters_.find(id);
  if (id < 1 || c == clusters_.end()) return;
  const Pose last = c->second.world_from_cluster.empty() ? Pose::Identity()
                                                         : c->second.world_from_cluster.rbegin()->second;
  const auto release = [&](LandmarkState& state) {
    state.cluster = -1;
    state.p_in_cluster = last * state.p_in_cluster;
  };
  for (auto& [l, state] : landmarks_)
    if (state.cluster == id) release(state);
  if (const auto r = retired_by_cluster_.find(id); r != retired_by_cluster_.end()) {
    for (int l : r->second)
      if (LandmarkState* state = retired_.Find(l); state && state->cluster == id) release(*state);
    retired_by_cluster_.erase(r);
  }
  clusters_.erase(c);
}

void MapState::ErasePose(int id, int frame) {
  if (const auto c = clusters_.find(id); id >= 1 && c != clusters_.end())
    c->second.world_from_cluster.erase(frame);
}

void MapState::ReframeCluster(int id, const Pose& cluster_from_body) {
  const auto c = clusters_.find(id);
  if (id < 1 || c == clusters_.end()) return;
  for (auto& [f, pose] : c->second.world_from_cluster) pose = pose * cluster_from_body;
  for (auto& [f, poses] : c->second.window_poses)
    for (MapCluster::WindowPose& w : poses) w.world_from_cluster = w.world_from_cluster * cluster_from_body;
  const Pose body_from_cluster = cluster_from_body.inverse();
  for (auto& [l, state] : landmarks_)
    if (state.cluster == id) state.p_in_cluster = body_from_cluster * state.p_in_cluster;
  if (const auto r = retired_by_cluster_.find(id); r != retired_by_cluster_.end())
    for (int l : r->second)
      if (LandmarkState* state = retired_.Find(l); state && state->cluster == id)
        state->p_in_cluster = body_from_cluster * state->p_in_cluster;
}

void MapState::SetTrajectory(int id, std::map<int, Pose> world_from_cluster) {
  if (const auto c = clusters_.find(id); id >= 1 && c != clusters_.end())
    c->second.world_from_cluster = std::move(world_from_cluster);
}

void MapState::SetPositionInCluster(int landmark, const Eigen::Vector3d& p_in_cluster) {
  if (const auto it = landmarks_.find(landmark); it != landmarks_.end()) {
    it->second.p_in_cluster = p_in_cluster;
  } else if (LandmarkState* state = retired_.Find(landmark)) {
    state->p_in_cluster = p_in_cluster;
  }
}

void MapState::SetCameraPose(int frame, const Pose& world_from_cam) {
  if (frame >= num_frames()) world_from_cam_.resize(frame + 1);
  world_from_cam_[frame] = world_from_cam;
}

// A window cluster and a map cluster it shares landmarks with.
struct MapState::Candidate {
  int window_label, map_id, shared;
  double ratio;        // shared / the window cluster's landmarks
  double known_ratio;  // shared / those of them the map already knows
  double contained;    // shared / the map cluster's landmarks labelled in this window
};

// Which window cluster continues which map cluster, and how it was decided.
struct MapState::Association {
  std::map<int, int> window_to_map;
  std::map<int, bool> map_taken;
  std::map<int, bool> contained;   // by the containment test
  std::map<int, Pose> by_motion;   // window label → mapcluster_from_wincluster
  std::map<int, bool> to_static;   // folded into the static world by the motion test
  bool Free(int window_label, int map_id) {
    return !window_to_map.count(window_label) && !map_taken[map_id];
  }
  void Take(int window_label, int map_id) {
    window_to_map[window_label] = map_id;
    map_taken[map_id] = true;
  }
};

namespace {

// What a reappearance test found, for the debug log.
std::string DescribeReappearance(const Reappearance& r) {
  return fmt::format("back after {} frames: {:.2f} m from where it was carried ({:.2f} reachable, "
                     "{:.2f} uncertainty), speed changed by {:.1f} m/s ({:.1f} possible, {:.1f} "
                     "uncertainty)",
                     r.gap_frames, r.distance_m, r.allowed_m, r.uncertainty_m, r.speed_change_mps,
                     r.allowed_speed_change_mps, r.uncertainty_mps);
}

// Map ids of the window's labelled landmarks by window label, ascending.
std::map<int, std::vector<int>> GroupByLabel(const MotionEstimate& window,
                                             const std::vector<int>* ids) {
  std::map<int, std::vector<int>> members;
  for (int l = 0; l < static_cast<int>(window.landmark_cluster.size()); ++l)
    if (window.landmark_cluster[l] >= 0 && window.landmark_in_cluster[l].allFinite())
      members[window.landmark_cluster[l]].push_back(ids ? (*ids)[l] : l);
  return members;
}

// The window's cluster trajectories in map world coordinates.
std::map<int, Pose> InMapWorld(const ClusterMotion& motion, const Pose& map_from_window) {
  std::map<int, Pose> t;
  for (size_t k = 0; k < motion.frames.size(); ++k)
    t.emplace(motion.frames[k], map_from_window * motion.world_from_cluster[k]);
  return t;
}

}  // namespace

const Eigen::Vector3d& MapState::WindowPoint(const MotionEstimate& window, int landmark) const {
  if (!window_ids_) return window.landmark_in_cluster[landmark];
  const auto it = std::lower_bound(window_ids_->begin(), window_ids_->end(), landmark);
  CSLAM_CHECK(it != window_ids_->end() && *it == landmark, "landmark not in the window");
  return window.landmark_in_cluster[it - window_ids_->begin()];
}

WindowIntegration MapState::Integrate(const MotionEstimate& window, const std::vector<int>* ids) {
  CSLAM_CHECK(!ids || ids->size() >= window.landmark_cluster.size(),
              "a compact window needs a map id per landmark");
  window_ids_ = ids;
  WindowIntegration info;
  info.range = window.range;
  window_last_frame_ = window.range.end - 1;
  window_begins_.insert(std::upper_bound(window_begins_.begin(), window_begins_.end(),
                                         window.range.begin),
                        window.range.begin);
  window_ends_.insert(std::upper_bound(window_ends_.begin(), window_ends_.end(), window.range.end),
                      window.range.end);
  if (options_.retire_after_frames > 0) RetireBefore(window.range.begin - options_.retire_after_frames);
  CSLAM_CHECK(static_cast<int>(window.world_from_cam.size()) == window.range.size(),
              "window estimate needs one camera pose per frame");
  const Pose map_from_window = ChainCamera(window, &info);

  const std::map<int, std::vector<int>> members = GroupByLabel(window, ids);
  if (auto it = members.find(0); it != members.end()) {
    // A window that finds none of a moving cluster's landmarks moving has lost the body (too
    // far for its depth noise to show the motion), which says nothing against the motion the
    // map saw: its landmarks keep their cluster. Clusters that hold still are folded into
    // the static world by their trajectories (MergeAgreeingClusters).
    std::set<int> seen_moving;
    if (options_.keep_lost_members)
      for (const auto& [label, ids] : members)
        if (label != 0)
          for (int l : ids)
            if (const int c = ClusterOf(l); c >= 1) seen_moving.insert(c);
    for (int l : it->second) {
      if (const int c = ClusterOf(l); options_.keep_lost_members && c >= 1 && !seen_moving.count(c))
        continue;
      Assign(l, 0, map_from_window * WindowPoint(window, l));
    }
  }

  const std::vector<Candidate> candidates = AssociationCandidates(window, members);
  Association a;
  for (const auto& c : candidates) {
    if (c.map_id == 0) continue;  // the static world continues through the motion check only
    if (c.ratio < options_.association_overlap) break;
    if (a.Free(c.window_label, c.map_id)) a.Take(c.window_label, c.map_id);
  }
  AssociateByContainment(candidates, &a);
  AssociateByMotion(window, members, candidates, map_from_window, &a, &info);

  for (const auto& [label, ids] : members) {
    if (label == 0 || a.to_static.count(label)) continue;
    const ClusterMotion* motion = window.FindCluster(label);
    if (!motion || motion->frames.empty()) continue;
    IntegrateCluster(window, label, ids, *motion, a, map_from_window, &info);
  }
  if (options_.merge_agreeing_clusters) MergeAgreeingClusters(&info);
  if (auto log = GetLogger("system"); log->should_log(spdlog::level::debug)) {
    std::string pairs;
    for (const auto& [label, id] : info.cluster_map) pairs += fmt::format(" {}->{}", label, id);
    log->debug("map: window {}..{} clusters (window label->map id):{}", window.range.begin,
               window.range.end - 1, pairs);
  }
  window_ids_ = nullptr;
  return info;
}

// Chains the window to the newest map pose it shares (with refine_camera_from: the newest up
// to the window's frame k − 1, later ones are re-estimated here): the window's own first
// frames were estimated with less context than the map's older windows had.
Pose MapState::ChainCamera(const MotionEstimate& window, WindowIntegration* info) {
  const int begin = window.range.begin;
  Pose map_from_window = Pose::Identity();
  const int newest_anchor =
      options_.refine_camera_from > 0
          ? std::min(window.range.end, begin + options_.refine_camera_from)
          : window.range.end;
  for (int f = std::min(newest_anchor, num_frames()) - 1; f >= begin; --f) {
    if (world_from_cam_[f]) {
      info->anchor_frame = f;
      map_from_window = *world_from_cam_[f] * window.world_from_cam[f - begin].inverse();
      break;
    }
  }
  if (info->anchor_frame < 0 && num_frames() > 0) {
    // No shared frame: continue from the last known pose as if the window started there.
    for (int f = num_frames() - 1; f >= 0; --f) {
      if (world_from_cam_[f]) {
        map_from_window = *world_from_cam_[f] * window.world_from_cam[0].inverse();
        break;
      }
    }
    info->gap = true;
    gaps_.push_back(begin);
    GetLogger("system")->warn("window {}..{} shares no frame with the map: trajectory gap", begin,
                              window.range.end - 1);
  }
  for (int f = begin; f < window.range.end; ++f) {
    const bool refine = options_.refine_camera_from > 0 && f > info->anchor_frame &&
                        info->anchor_frame >= 0;
    if (f >= num_frames() || !world_from_cam_[f] || refine)
      SetCameraPose(f, map_from_window * window.world_from_cam[f - begin]);
  }
  return map_from_window;
}

// Candidate associations, strongest overlap first, one window cluster per map cluster.
std::vector<MapState::Candidate> MapState::AssociationCandidates(
    const MotionEstimate& window, const std::map<int, std::vector<int>>& members) const {
  std::map<int, int> in_window;  // map cluster → its landmarks the window labelled
  for (const auto& [label, ids] : members)
    for (int l : ids)
      if (const int c = ClusterOf(l); c >= 1) ++in_window[c];
  std::vector<Candidate> candidates;
  for (const auto& [label, ids] : members) {
    if (label == 0) continue;
    std::map<int, int> shared;
    int known = 0;
    for (int l : ids) {
      const int c = ClusterOf(l);
      if (c >= 0) ++shared[c], ++known;
    }
    for (const auto& [map_id, count] : shared)
      candidates.push_back({label, map_id, count, double(count) / double(ids.size()),
                            double(count) / double(known),
                            map_id >= 1 ? double(count) / double(in_window[map_id]) : 0.0});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.ratio != b.ratio ? a.ratio > b.ratio : a.window_label < b.window_label;
  });
  auto log = GetLogger("system");
  if (log->should_log(spdlog::level::debug))
    for (const auto& c : candidates)
      log->debug("map: window {}..{} cluster {} ({} landmarks) vs map cluster {}: {} shared, "
                 "overlap {:.2f}, known {:.2f}, contained {:.2f}",
                 window.range.begin, window.range.end - 1, c.window_label,
                 members.at(c.window_label).size(), c.map_id, c.shared, c.ratio, c.known_ratio,
                 c.contained);
  return candidates;
}

// Containment test (see MapStateOptions): the object's part still in view moved wholesale
// into this window cluster, which the newly tracked landmarks only diluted.
void MapState::AssociateByContainment(const std::vector<Candidate>& candidates,
                                      Association* a) const {
  std::vector<Candidate> by_contained = candidates;
  std::stable_sort(by_contained.begin(), by_contained.end(),
                   [](const Candidate& x, const Candidate& y) { return x.contained > y.contained; });
  for (const auto& c : by_contained) {
    if (c.contained < options_.containment_overlap) break;
    if (c.known_ratio < options_.known_overlap || c.shared < options_.min_shared_for_alignment ||
        !a->Free(c.window_label, c.map_id))
      continue;
    a->Take(c.window_label, c.map_id);
    a->contained[c.window_label] = true;
  }
}

// Motion-checked association below association_overlap (see MapStateOptions). The static
// world (0) is a candidate too: a window cluster made of map-static landmarks that holds
// still in the map was the static world all along.
void MapState::AssociateByMotion(const MotionEstimate& window,
                                 const std::map<int, std::vector<int>>& members,
                                 const std::vector<Candidate>& candidates,
                                 const Pose& map_from_window, Association* a,
                                 WindowIntegration* info) {
  auto log = GetLogger("system");
  std::vector<Candidate> by_known = candidates;
  std::stable_sort(by_known.begin(), by_known.end(), [](const Candidate& x, const Candidate& y) {
    return x.known_ratio > y.known_ratio;
  });
  for (const auto& c : by_known) {
    if (!options_.motion_association || c.known_ratio < options_.known_overlap) break;
    if (a->window_to_map.count(c.window_label) || a->to_static.count(c.window_label) ||
        (c.map_id >= 1 && a->map_taken[c.map_id]))
      continue;
    const ClusterMotion* motion = window.FindCluster(c.window_label);
    if (!motion || motion->frames.empty()) continue;
    const std::map<int, Pose> win = InMapWorld(*motion, map_from_window);
    std::vector<Eigen::Vector3d> points;
    for (int l : members.at(c.window_label)) points.push_back(WindowPoint(window, l));
    // By reference: `cond ? prvalue : lvalue` would copy the map cluster's whole trajectory.
    const std::map<int, Pose> still = c.map_id == 0 ? StaticTrajectory(win) : std::map<int, Pose>{};
    const std::map<int, Pose>& map_trajectory =
        c.map_id == 0 ? still : clusters_[c.map_id].world_from_cluster;
    const MotionAgreement agreement = CompareMotions(map_trajectory, win, points, world_from_cam_);
    log->debug("map: window cluster {} vs map cluster {}: motion over {} frames, RMS {:.3f} m, "
               "relative {:.4f}", c.window_label, c.map_id, agreement.frames, agreement.rms_m,
               agreement.relative_rms());
    if (agreement.frames < options_.motion_min_frames || agreement.relative_rms() > options_.motion_tolerance)
      continue;
    if (c.map_id == 0) {
      a->to_static[c.window_label] = true;
      info->cluster_map.emplace_back(c.window_label, 0);
      for (int l : members.at(c.window_label))
        Assign(l, 0, agreement.a_from_b * WindowPoint(window, l));
      ++info->by_motion;
      continue;
    }
    a->Take(c.window_label, c.map_id);
    a->by_motion[c.window_label] = agreement.a_from_b;
  }
}

// How a window cluster's frame maps into map cluster `map_id`'s: by the trajectories' offset
// (stitch_by_motion), else by the shared landmarks, else at the newest shared frame; nullopt
// when nothing ties them.
std::optional<Pose> MapState::AlignToMapCluster(const MotionEstimate& window, int map_id,
                                                const std::vector<int>& ids,
                                                const ClusterMotion& motion,
                                                const Pose& map_from_window) {
  const MapCluster& mc = clusters_[map_id];
  if (options_.stitch_by_motion) {
    std::vector<Eigen::Vector3d> points;
    for (int l : ids) points.push_back(WindowPoint(window, l));
    const MotionAgreement stitch = CompareMotions(
        mc.world_from_cluster, InMapWorld(motion, map_from_window), points, world_from_cam_);
    if (stitch.frames >= options_.motion_min_frames) return stitch.a_from_b;
  }
  std::vector<Eigen::Vector3d> src, dst;  // shared landmarks
  for (int l : ids) {
    if (ClusterOf(l) != map_id) continue;
    src.push_back(WindowPoint(window, l));
    dst.push_back(landmarks_[l].p_in_cluster);
  }
  if (static_cast<int>(src.size()) >= options_.min_shared_for_alignment)
    return AlignUmeyama(src, dst, false).rigid;
  for (size_t k = motion.frames.size(); k-- > 0;) {
    const auto pose = mc.world_from_cluster.find(motion.frames[k]);
    if (pose == mc.world_from_cluster.end()) continue;
    return Pose(pose->second.inverse() * map_from_window * motion.world_from_cluster[k]);
  }
  return std::nullopt;
}

// Continues the associated map cluster with a window cluster, or starts a new one.
void MapState::IntegrateCluster(const MotionEstimate& window, int label, const std::vector<int>& ids,
                                const ClusterMotion& motion, const Association& a,
                                const Pose& map_from_window, WindowIntegration* info) {
  // mapcluster_from_wincluster maps the window's cluster frame into the map's.
  Pose mapcluster_from_wincluster = Pose::Identity();
  int map_id = -1;
  if (auto it = a.window_to_map.find(label); it != a.window_to_map.end()) {
    std::optional<Pose> aligned;
    if (auto m = a.by_motion.find(label); m != a.by_motion.end()) {
      // The shared landmarks may be the mislabelled few: trust the motion's offset.
      aligned = m->second;
      ++info->by_motion;
    } else {
      aligned = AlignToMapCluster(window, it->second, ids, motion, map_from_window);
    }
    if (aligned) {
      mapcluster_from_wincluster = *aligned;
      map_id = it->second;
      ++info->associated;
      if (a.contained.count(label)) ++info->by_containment;
    }
  }
  if (map_id < 0 && static_cast<int>(ids.size()) < options_.min_new_cluster_landmarks) {
    ++info->dropped;
    return;
  }
  if (map_id < 0) {
    map_id = next_cluster_id_++;
    clusters_[map_id].id = map_id;
    mapcluster_from_wincluster = Pose::Identity();
    ++info->created;
  }
  info->cluster_map.emplace_back(label, map_id);
  ++clusters_[map_id].windows;
  MapCluster& mc = clusters_[map_id];
  const Pose wincluster_from_mapcluster = mapcluster_from_wincluster.inverse();
  const int source = next_window_source_++;
  for (size_t k = 0; k < motion.frames.size(); ++k) {
    // Keep poses already in the map so the published trajectory never changes under a
    // reader's feet; the window only extends it.
    const Pose pose = map_from_window * motion.world_from_cluster[k] * wincluster_from_mapcluster;
    mc.world_from_cluster.try_emplace(motion.frames[k], pose);
    mc.window_poses[motion.frames[k]].push_back({source, pose});
  }
  for (int l : ids) Assign(l, map_id, mapcluster_from_wincluster * WindowPoint(window, l));
}

void MapState::Assign(int landmark, int cluster, const Eigen::Vector3d& p_in_cluster) {
  if (const LandmarkState* r = retired_.Find(landmark)) {  // seen again: live again
    if (r->cluster >= 1) std::erase(retired_by_cluster_[r->cluster], landmark);
    landmarks_.emplace(landmark, *r);
    retired_.Erase(landmark);
  }
  auto& state = landmarks_.try_emplace(landmark).first->second;
  state.last_frame = window_last_frame_;
  if (state.cluster >= 1 && state.cluster != cluster) {
    auto it = clusters_.find(state.cluster);
    if (it != clusters_.end()) --it->second.num_landmarks;
  }
  if (cluster >= 1 && state.cluster != cluster) ++clusters_[cluster].num_landmarks;
  state.cluster = cluster;
  state.p_in_cluster = p_in_cluster;
}

std::map<int, std::vector<int>> MapState::MembersByCluster() const {
  std::map<int, std::vector<int>> members;
  for (const auto& [l, state] : landmarks_)
    if (state.cluster >= 0) members[state.cluster].push_back(l);
  for (auto& [c, ids] : members) std::sort(ids.begin(), ids.end());
  return members;
}

void MapState::MergeInto(int older, int younger, const Pose& older_from_younger) {
  const auto members = MembersByCluster();
  if (const auto it = members.find(younger); it != members.end())
    for (int l : it->second) {
      const int last = landmarks_[l].last_frame;
      Assign(l, older, older_from_younger * landmarks_[l].p_in_cluster);
      landmarks_[l].last_frame = last;  // a merge is no sighting
    }
  if (const auto it = retired_by_cluster_.find(younger); it != retired_by_cluster_.end()) {
    // Retired landmarks follow their cluster (counted as members by the Assign above: none).
    for (int l : it->second) {
      LandmarkState& state = *retired_.Find(l);
      state.cluster = older;
      state.p_in_cluster = older_from_younger * state.p_in_cluster;
      if (older >= 1) ++clusters_[older].num_landmarks;
    }
    if (older >= 1) {
      auto& target = retired_by_cluster_[older];
      target.insert(target.end(), it->second.begin(), it->second.end());
    }
    retired_by_cluster_.erase(it);
  }
  if (older >= 1) {
    MapCluster& o = clusters_[older];
    o.windows += clusters_[younger].windows;
    const Pose younger_from_older = older_from_younger.inverse();
    for (const auto& [f, pose] : clusters_[younger].world_from_cluster)
      o.world_from_cluster.try_emplace(f, pose * younger_from_older);
    for (const auto& [f, poses] : clusters_[younger].window_poses)
      for (const MapCluster::WindowPose& w : poses)
        o.window_poses[f].push_back({w.source, w.world_from_cluster * younger_from_older});
  }
  clusters_.erase(younger);
}

bool MapState::CoLocated(const MapCluster& older, const std::vector<int>& older_ids,
                         const MapCluster& younger,
                         const std::vector<Eigen::Vector3d>& younger_points) const {
  if (!(options_.co_location_ratio > 0)) return false;
  const CoLocation loc = CompareLocations(older.world_from_cluster, PointsOf(older_ids),
                                          younger.world_from_cluster, younger_points);
  return loc.frames >= options_.co_location_min_frames &&
         loc.median_ratio <= options_.co_location_ratio;
}

std::vector<Eigen::Vector3d> MapState::PointsOf(const std::vector<int>& ids) const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(ids.size());
  for (int l : ids) points.push_back(landmarks_.at(l).p_in_cluster);
  return points;
}

std::map<int, std::vector<Eigen::Vector3d>> MapState::MovingClusterPoints() const {
  std::map<int, std::vector<Eigen::Vector3d>> points;
  for (int l : Landmarks())
    if (const int c = ClusterOf(l); c >= 1 && clusters_.count(c)) points[c].push_back(*PositionInCluster(l));
  return points;
}

bool MapState::ApartByGap(const std::vector<Eigen::Vector3d>& a, const Pose& a_from_b,
                          const std::vector<Eigen::Vector3d>& b) const {
  if (!(options_.split_gap_m > 0)) return false;
  std::vector<Eigen::Vector3d> moved;
  moved.reserve(b.size());
  for (const Eigen::Vector3d& x : b) moved.push_back(a_from_b * x);
  return SeparatedByGap(a, moved, options_.split_gap_m);
}

std::vector<std::pair<int, int>> MapState::MergeCoLocatedClusters(
    const std::function<double(int)>& position_sigma_m) {
  // χ²₃ at 95 %: the squared misplacement of a point by two tracks of one body, each with a
  // per-axis position error σ, is within 7.81 (σ_a² + σ_b²) but for one frame in twenty.
  constexpr double kChi2For3Dof95 = 7.815;
  std::vector<std::pair<int, int>> merged;
  if (!(options_.co_location_ratio > 0)) return merged;
  for (bool again = true; again;) {
    again = false;
    const std::map<int, std::vector<Eigen::Vector3d>> points = MovingClusterPoints();
    for (const auto& [younger, younger_points] : points) {
      // As in the windows' merge test: fewer than 3 points do not fix a body's place.
      if (younger_points.size() < 3) continue;
      const MapCluster& y = clusters_.at(younger);
      for (const auto& [older, older_points] : points) {
        if (older >= younger) break;
        if (older_points.size() < 3) continue;
        const MapCluster& o = clusters_.at(older);
        const CoLocation loc =
            CompareLocations(o.world_from_cluster, older_points, y.world_from_cluster, younger_points);
        if (loc.frames < options_.co_location_min_frames) continue;
        // A hand-over: too few shared frames for the motion test, and the windows judged the
        // place test on poses metres off.
        const bool hand_over = loc.frames < options_.motion_min_frames;
        if (hand_over && loc.median_ratio > options_.co_location_ratio) continue;
        const MotionAgreement offset =
            CompareMotions(o.world_from_cluster, y.world_from_cluster, younger_points, world_from_cam_);
        // Pairs that share motion_min_frames frames were judged by the windows' motion test,
        // on their noisy poses, and kept apart: two bodies close together, clusters that each
        // hold parts of two, or a far car's pieces. The tracks can tell the last: one rigid
        // motion to the motion test's tolerance, or, in one place, within the tracks' own
        // errors; and not metres apart (the map's own merge rule, step 3). Clusters that each
        // hold parts of two cars do not move rigidly.
        const double sigma2 = position_sigma_m ? std::pow(position_sigma_m(older), 2) +
                                                     std::pow(position_sigma_m(younger), 2)
                                               : 0.0;
        const bool within_noise = sigma2 > 0 && loc.median_ratio <= options_.co_location_ratio &&
                                  offset.rms_m * offset.rms_m <= kChi2For3Dof95 * sigma2;
        const bool one_motion =
            offset.frames >= options_.motion_min_frames &&
            (offset.relative_rms() <= options_.motion_tolerance || within_noise);
        const bool apart = one_motion && (options_.split_gap_m > 0
                                              ? ApartByGap(older_points, offset.a_from_b, younger_points)
                                              : loc.median_ratio > options_.co_location_ratio);
        if (!hand_over && (!one_motion || apart)) {
          GetLogger("system")->debug(
              "object {} stays apart from {} at the end: {} shared frames, centres {:.2f} of the "
              "smaller extent apart, motions {:.4f} apart over {} frames ({:.2f} m, tracks' error "
              "{:.2f} m){}",
              younger, older, loc.frames, loc.median_ratio, offset.relative_rms(), offset.frames,
              offset.rms_m, std::sqrt(sigma2), apart ? ", in two places" : "");
          continue;
        }
        GetLogger("system")->debug("object {} merged into {} at the end: {} shared frames, centres "
                                   "{:.2f} of the smaller extent apart, motions {:.4f} apart "
                                   "({:.2f} m, tracks' error {:.2f} m)",
                                   younger, older, loc.frames, loc.median_ratio,
                                   offset.relative_rms(), offset.rms_m, std::sqrt(sigma2));
        MergeInto(older, younger, offset.a_from_b);
        merged.emplace_back(older, younger);
        again = true;
        break;
      }
      if (again) break;
    }
  }
  return merged;
}

std::vector<std::pair<int, int>> MapState::MergeReappearedClusters(const ReappearanceGate& gate) {
  std::vector<std::pair<int, int>> merged;
  if (!(gate.max_gap_s > 0)) return merged;
  for (bool again = true; again;) {
    again = false;
    // Retired landmarks too: a piece may have ended long ago.
    const std::map<int, std::vector<Eigen::Vector3d>> points = MovingClusterPoints();
    // Each later piece joins the earlier one its start is best explained by; a piece that two
    // earlier bodies could both have become is left alone, since a wrong join corrupts a
    // trajectory where a missed one costs an id.
    for (const auto& [b, b_points] : points) {
      // As in the place test: fewer than 3 points do not fix a body's place.
      if (b_points.size() < 3) continue;
      const MapCluster& bc = clusters_.at(b);
      std::optional<std::pair<int, Reappearance>> best;
      int reachable = 0;
      for (const auto& [a, a_points] : points) {
        if (a == b || a_points.size() < 3) continue;
        const MapCluster& ac = clusters_.at(a);
        if (!WithinGap(ac.world_from_cluster, bc.world_from_cluster, gate)) continue;
        const Reappearance r = CompareAcrossGap(ac.world_from_cluster, a_points,
                                                bc.world_from_cluster, b_points, gate);
        if (GetLogger("system")->should_log(spdlog::level::debug))
          GetLogger("system")->debug("object {} as {} {}{}", a, b, DescribeReappearance(r),
                                     r.Reachable() ? ": reachable" : "");
        if (!r.Reachable()) continue;
        ++reachable;
        if (!best || r.Score() < best->second.Score()) best.emplace(a, r);
      }
      if (reachable != 1) continue;
      const auto& [a, r] = *best;
      GetLogger("system")->debug("object {} merged into {} at the end: back after {} frames", b,
                                 a, r.gap_frames);
      MergeInto(a, b, r.a_from_b);
      merged.emplace_back(a, b);
      again = true;
      break;
    }
  }
  return merged;
}

void MapState::MergeAgreeingClusters(WindowIntegration* info) {
  ReappearanceGate gate;
  gate.frame_period_s = options_.frame_period_s;
  gate.max_gap_s = options_.reappearance_max_gap_s;
  gate.max_acceleration_mps2 = options_.reappearance_max_acceleration_mps2;
  // Oldest first, so a chain of fragments folds into the oldest id; repeat until nothing
  // merges, since a merge extends the older trajectory over frames it may now share.
  for (bool merged = true; merged;) {
    merged = false;
    const auto members = MembersByCluster();
    for (const auto& [younger, ids] : members) {
      if (younger == 0) continue;
      // Fewer than 3 points do not fix a rigid body's pose: such a cluster's trajectory can
      // agree with an object's over a few frames by chance, and the merge would then extend
      // the object with its poses (KITTI raw 0005: a 2-landmark cluster carried the van astray;
      // docs/experiments/2026-12-03-object-pose-noise-and-motion-prior.md).
      if (ids.size() < 3) continue;
      const auto y = clusters_.find(younger);
      if (y == clusters_.end() || y->second.world_from_cluster.empty()) continue;
      const std::vector<Eigen::Vector3d> points = PointsOf(ids);
      MapCluster recent;  // the younger cluster over the merge horizon
      const auto& whole = y->second.world_from_cluster;
      const int horizon = options_.merge_horizon_frames;
      recent.world_from_cluster.insert(
          horizon > 0 ? whole.lower_bound(whole.rbegin()->first - horizon + 1) : whole.begin(),
          whole.end());
      std::optional<std::pair<int, Reappearance>> reappeared;  // the nearest old body
      for (const auto& [older, older_ids] : members) {
        if (older >= younger) break;
        const auto o = clusters_.find(older);
        if (older >= 1 && o == clusters_.end()) continue;
        const std::map<int, Pose> still =
            older == 0 ? StaticTrajectory(recent.world_from_cluster) : std::map<int, Pose>{};
        const MotionAgreement agreement =
            CompareMotions(older == 0 ? still : o->second.world_from_cluster,
                           recent.world_from_cluster, points, world_from_cam_,
                           std::min(options_.motion_min_frames, options_.co_location_min_frames),
                           options_.merge_max_frames);
        if (agreement.frames == 0) {
          if (older >= 1 && WithinGap(o->second.world_from_cluster, whole, gate)) {
            const Reappearance r = CompareAcrossGap(o->second.world_from_cluster,
                                                    PointsOf(older_ids), whole, points, gate);
            if (r.compared > 0 && !r.Reachable() &&
                GetLogger("system")->should_log(spdlog::level::debug))
              GetLogger("system")->debug("map cluster {} not back as {}: {}", older, younger,
                                         DescribeReappearance(r));
            if (r.Reachable() && (!reappeared || r.Score() < reappeared->second.Score()))
              reappeared.emplace(older, r);
          }
          continue;
        }
        const bool rigid = agreement.frames >= options_.motion_min_frames &&
                           agreement.relative_rms() <= options_.motion_tolerance;
        if (!rigid && !(older >= 1 && CoLocated(o->second, older_ids, recent, points)))
          continue;
        // One motion, but two places with nothing between: cars one behind the other.
        if (older >= 1 && options_.split_gap_m > 0 &&
            ApartByGap(PointsOf(older_ids), agreement.a_from_b, points))
          continue;
        GetLogger("system")->debug("map cluster {} merged into {} ({} shared frames, RMS {:.3f} m, {})",
                                   younger, older, agreement.frames, agreement.rms_m,
                                   rigid ? "one rigid motion" : "in one place");
        MergeInto(older, younger, agreement.a_from_b);
        info->merged.emplace_back(older, younger);
        merged = true;
        break;
      }
      if (!merged && reappeared) {
        const auto& [older, r] = *reappeared;
        GetLogger("system")->debug(
            "map cluster {} merged into {} (back after {} frames: {:.2f} m from where it was "
            "carried, {:.2f} m reachable of which {:.2f} uncertainty; speed changed by {:.1f} "
            "m/s, {:.1f} possible of which {:.1f} uncertainty)",
            younger, older, r.gap_frames, r.distance_m, r.allowed_m, r.uncertainty_m,
            r.speed_change_mps, r.allowed_speed_change_mps, r.uncertainty_mps);
        MergeInto(older, younger, r.a_from_b);
        info->merged.emplace_back(older, younger);
        merged = true;
      }
      if (merged) break;
    }
  }
}

}  // namespace cslam
