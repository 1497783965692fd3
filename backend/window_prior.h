#pragma once
// What the online map already knows about a backend window [ours]: with 30-frame windows every
// 5 frames, 25 of a window's frames already have camera poses in the map and most of its
// landmarks a cluster and a position. RunClusterSlam's warm start (backend/clusterslam.h)
// starts from this instead of clustering and initialising the window from scratch.
//
// Frames: everything is in the window's own frame, world = the left camera at range.begin
// (the frame of every backend estimate, backend/motion_estimation.h), so a prior's camera pose
// at range.begin is the identity. Labels are the map's cluster ids (0 = static world); the
// backend relabels its output as usual (0 static, 1..K moving).
//
// Moving clusters carry only their labels: their shapes and trajectories are re-initialised
// from the window's own observations (noise-aware shape initialisation is a small part of a
// window's time), because the map's cluster trajectories are stitched from earlier windows and
// carry their cross-window drift (docs/experiments/2026-11-23-online-map-merging-clusters.md).
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/shape_init.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// A backend window's prior from the map; see the file comment.
struct WindowPrior {
  FrameRange range;
  /// [landmark id]: the map's cluster (0 static, > 0 a map cluster id), -1 unknown to the map.
  std::vector<int> landmark_cluster;
  /// [landmark id]: static landmarks' positions in the window's world frame; NaN otherwise.
  std::vector<Eigen::Vector3d> static_point;
  /// [frame - range.begin]: the camera pose in the window's world frame where the map has one.
  std::vector<std::optional<Pose>> world_from_cam;

  /// Frames of the range with a camera pose.
  int KnownFrames() const;
  /// The map's cluster of `landmark` (-1 for ids beyond the prior).
  int ClusterOf(int landmark) const;
};

/// A camera pose for every frame of prior.range: the prior's where it has one; otherwise the
/// frame is registered (noise-aware ICP, backend/shape_init.h, with `options`' Huber threshold
/// and Gauss–Newton limits) on the prior's static landmarks it observes, starting from a
/// constant-velocity prediction of its neighbours. A frame observing fewer than
/// options.min_points of them keeps the prediction. Frames are completed outwards from the
/// known ones (forwards after them, backwards before them). Precondition: KnownFrames() > 0.
std::vector<Pose> CompleteCameraPoses(const WindowPrior& prior, const TrackletTable& table,
                                      const StereoCamera& camera, const ShapeInitOptions& options);

}  // namespace cslam
