#pragma once
// A simple stand-in for EstimateMotions, used to test the outer loop on its own: per cluster,
// frame-to-model point-to-point registration (Umeyama) of the back-projections, landmarks
// initialised at first sight. No covariances, no bundle adjustment.
#include <cmath>
#include <limits>

#include "backend/motion_estimation.h"

namespace cslam::testing {

inline MotionEstimate FakeEstimateMotions(const TrackletTable& table, const StereoCamera& camera,
                                          FrameRange range, const std::vector<int>& labels,
                                          const MotionEstimationOptions&,
                                          const MotionEstimate* = nullptr) {
  MotionEstimate est;
  est.range = range;
  est.landmark_cluster = labels;
  const int n = table.num_landmarks();
  est.landmark_cluster.resize(n, -1);
  est.landmark_in_cluster.assign(
      n, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  est.world_from_cam.assign(range.size(), Pose::Identity());
  int num_labels = 0;
  for (int q : est.landmark_cluster) num_labels = std::max(num_labels, q + 1);
  for (int q = 0; q < num_labels; ++q) {
    ClusterMotion motion;
    motion.cluster = q;
    bool started = false;
    Pose last = Pose::Identity();
    for (int t = range.begin; t < range.end; ++t) {
      std::vector<Eigen::Vector3d> src, dst;
      std::vector<std::pair<int, Eigen::Vector3d>> fresh;
      for (const auto& ref : table.ObservationsAt(t)) {
        if (est.landmark_cluster[ref.landmark] != q) continue;
        Eigen::Vector3d p;
        if (!camera.BackProject<double>(table.Get(ref).x, &p)) continue;
        const Eigen::Vector3d& model = est.landmark_in_cluster[ref.landmark];
        if (model.allFinite()) {
          src.push_back(p);
          dst.push_back(model);
        } else {
          fresh.emplace_back(ref.landmark, p);
        }
      }
      Pose cluster_from_cam;
      bool have_pose = false;
      if (!started && (q == 0 ? t == range.begin : fresh.size() >= 3)) {
        cluster_from_cam = Pose::Identity();
        started = have_pose = true;
      } else if (started && src.size() >= 3) {
        cluster_from_cam = AlignUmeyama(src, dst, false).rigid;
        have_pose = true;
      }
      if (!have_pose) {
        if (q == 0) est.world_from_cam[t - range.begin] = last;
        continue;
      }
      last = cluster_from_cam;
      for (const auto& [l, p] : fresh) est.landmark_in_cluster[l] = cluster_from_cam * p;
      if (q == 0) {
        est.world_from_cam[t - range.begin] = cluster_from_cam;
      } else {
        motion.frames.push_back(t);
        motion.cam_from_cluster.push_back(cluster_from_cam.inverse());
        motion.world_from_cluster.push_back(est.world_from_cam[t - range.begin] *
                                            cluster_from_cam.inverse());
      }
    }
    if (q > 0) est.clusters.push_back(std::move(motion));
  }
  return est;
}

}  // namespace cslam::testing
