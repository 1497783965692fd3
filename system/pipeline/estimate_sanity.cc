#include "system/pipeline/estimate_sanity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <map>

#include <spdlog/fmt/fmt.h>

namespace cslam {

void EstimateSanityOptions::Check() const {
  CheckOption(std::isfinite(max_step_depths) && max_step_depths > 0, "max_step_depths",
              "must be > 0", max_step_depths);
  CheckOption(std::isfinite(far_landmark_depths) && far_landmark_depths >= 1,
              "far_landmark_depths", "must be >= 1", far_landmark_depths);
  CheckOption(max_far_landmark_fraction >= 0 && max_far_landmark_fraction <= 1,
              "max_far_landmark_fraction", "must be in [0, 1]", max_far_landmark_fraction);
  CheckOption(max_cluster_depth_ratio == 0 || max_cluster_depth_ratio >= 1,
              "max_cluster_depth_ratio", "must be 0 (off) or >= 1", max_cluster_depth_ratio);
}

void EstimateSanityOptions::Load(OptionsReader& reader) {
  reader.Read("max_step_depths", &max_step_depths);
  reader.Read("far_landmark_depths", &far_landmark_depths);
  reader.Read("max_far_landmark_fraction", &max_far_landmark_fraction);
  reader.Read("max_cluster_depth_ratio", &max_cluster_depth_ratio);
}

namespace {

EstimateSanity Refuse(EstimateSanity s, std::string reason) {
  s.usable = false;
  s.reason = std::move(reason);
  return s;
}

}  // namespace

EstimateSanity JudgeEstimate(const MotionEstimate& e, const TrackletTable& table,
                             const StereoCamera& camera, const EstimateSanityOptions& options) {
  EstimateSanity s;
  const FrameRange range = e.range;
  if (range.size() <= 0 || static_cast<int>(e.world_from_cam.size()) != range.size())
    return Refuse(s, "no camera pose per frame");
  for (const Pose& p : e.world_from_cam)
    if (!p.matrix().allFinite()) return Refuse(s, "a non-finite camera pose");
  for (const ClusterMotion& c : e.clusters)
    for (const Pose& p : c.world_from_cluster)
      if (!p.matrix().allFinite()) return Refuse(s, fmt::format("a non-finite pose of cluster {}", c.cluster));

  // D: the farthest point the stereo pair measured in the window.
  for (int f = range.begin; f < range.end && f < table.num_frames(); ++f)
    for (const ObservationRef& ref : table.ObservationsAt(f)) {
      Eigen::Vector3d p;
      if (camera.BackProject<double>(table.Get(ref).x, &p)) s.max_depth_m = std::max(s.max_depth_m, p.z());
    }
  if (!(s.max_depth_m > 0)) return s;  // nothing measured: nothing to compare against

  for (size_t k = 1; k < e.world_from_cam.size(); ++k)
    s.max_step_m = std::max(s.max_step_m, (e.world_from_cam[k].translation() -
                                           e.world_from_cam[k - 1].translation()).norm());
  if (s.max_step_m > options.max_step_depths * s.max_depth_m)
    return Refuse(s, fmt::format("a camera step of {:.3g} m, more than {} x the farthest measured "
                                 "depth ({:.3g} m)", s.max_step_m, options.max_step_depths,
                                 s.max_depth_m));

  // Landmarks, in each observing camera: static ones through the camera pose, moving ones
  // through their cluster's cam_from_cluster at that frame.
  std::map<int, const ClusterMotion*> by_label;
  for (const ClusterMotion& m : e.clusters) by_label[m.cluster] = &m;
  std::vector<Pose> cam_from_world;
  for (const Pose& p : e.world_from_cam) cam_from_world.push_back(p.inverse());
  const double limit = options.far_landmark_depths * s.max_depth_m;
  const int n = std::min<int>(static_cast<int>(e.landmark_cluster.size()), table.num_landmarks());
  for (int i = 0; i < n; ++i) {
    const int label = e.landmark_cluster[i];
    const Eigen::Vector3d& x = e.landmark_in_cluster[i];
    if (label < 0) continue;
    if (!x.allFinite()) {
      ++s.landmarks, ++s.far_landmarks;
      continue;
    }
    const ClusterMotion* m = nullptr;
    if (label > 0) {
      auto it = by_label.find(label);
      if (it == by_label.end()) continue;
      m = it->second;
    }
    ++s.landmarks;
    for (const StereoObservation& o : table.ObservationsOf(i, range)) {
      Eigen::Vector3d p;
      if (m) {
        auto f = std::lower_bound(m->frames.begin(), m->frames.end(), o.frame);
        if (f == m->frames.end() || *f != o.frame) continue;
        p = m->cam_from_cluster[f - m->frames.begin()] * x;
      } else {
        p = cam_from_world[o.frame - range.begin] * x;
      }
      if (p.norm() > limit) {
        ++s.far_landmarks;
        break;
      }
    }
  }
  if (s.landmarks > 0 && s.far_landmarks > options.max_far_landmark_fraction * s.landmarks)
    return Refuse(s, fmt::format("{} of {} landmarks lie more than {} x the farthest measured depth "
                                 "({:.3g} m) from a camera that sees them",
                                 s.far_landmarks, s.landmarks, options.far_landmark_depths,
                                 s.max_depth_m));
  return s;
}

int DropImplausibleClusterPoses(MotionEstimate* e, const TrackletTable& table,
                                const StereoCamera& camera, const EstimateSanityOptions& options) {
  if (options.max_cluster_depth_ratio <= 0) return 0;
  // Each frame's observations are walked once, each one's depth ratio filed under its
  // cluster's pose at that frame: ratios[cluster index][pose index].
  std::map<int, size_t> index_of;
  for (size_t c = 0; c < e->clusters.size(); ++c) index_of[e->clusters[c].cluster] = c;
  std::vector<std::vector<std::vector<double>>> ratios(e->clusters.size());
  for (size_t c = 0; c < e->clusters.size(); ++c) ratios[c].resize(e->clusters[c].frames.size());
  for (int f = e->range.begin; f < e->range.end && f < table.num_frames(); ++f)
    for (const ObservationRef& ref : table.ObservationsAt(f)) {
      const int l = ref.landmark;
      if (l >= static_cast<int>(e->landmark_cluster.size()) || e->landmark_cluster[l] < 1) continue;
      const auto c = index_of.find(e->landmark_cluster[l]);
      if (c == index_of.end()) continue;
      const ClusterMotion& m = e->clusters[c->second];
      const auto k = std::lower_bound(m.frames.begin(), m.frames.end(), f);
      if (k == m.frames.end() || *k != f) continue;
      Eigen::Vector3d measured;
      if (!camera.BackProject<double>(table.Get(ref).x, &measured) || !(measured.z() > 0)) continue;
      const double z = (m.cam_from_cluster[k - m.frames.begin()] * e->landmark_in_cluster[l]).z();
      // Behind the camera counts as infinitely far.
      ratios[c->second][k - m.frames.begin()].push_back(
          z > 0 ? z / measured.z() : std::numeric_limits<double>::infinity());
    }
  int dropped = 0;
  std::vector<int> emptied;
  for (size_t c = 0; c < e->clusters.size(); ++c) {
    ClusterMotion& m = e->clusters[c];
    ClusterMotion kept;
    kept.cluster = m.cluster;
    for (size_t k = 0; k < m.frames.size(); ++k) {
      std::vector<double>& r = ratios[c][k];
      bool absurd = false;
      if (!r.empty()) {
        std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
        absurd = !(r[r.size() / 2] <= options.max_cluster_depth_ratio);
      }
      if (absurd) {
        ++dropped;
        continue;
      }
      kept.frames.push_back(m.frames[k]);
      kept.cam_from_cluster.push_back(m.cam_from_cluster[k]);
      kept.world_from_cluster.push_back(m.world_from_cluster[k]);
    }
    if (kept.frames.empty() && !m.frames.empty()) emptied.push_back(m.cluster);
    m = std::move(kept);
  }
  if (!emptied.empty()) {
    std::erase_if(e->clusters, [](const ClusterMotion& m) { return m.frames.empty(); });
    for (size_t l = 0; l < e->landmark_cluster.size(); ++l)
      if (std::find(emptied.begin(), emptied.end(), e->landmark_cluster[l]) != emptied.end()) {
        e->landmark_cluster[l] = -1;
        e->landmark_in_cluster[l] = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
      }
  }
  return dropped;
}

}  // namespace cslam
