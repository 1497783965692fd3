#include "system/map/object_tracks.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <optional>

#include "core/logging.h"
#include "system/map/medoid.h"

namespace cslam {

namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// The pose measurement a frame's visible landmarks give: the inverse of their Fisher
// information for a rigid body's rotation (left, world) and position, each point with the
// stereo covariance of its projection. False with fewer than 3 usable points.
bool PoseCovariance(const std::vector<Eigen::Vector3d>& body_points, const Pose& world_from_body,
                    const Pose& world_from_cam, const StereoCamera& camera,
                    const Eigen::Matrix3d& pixel_cov, Eigen::Matrix3d* rotation_cov,
                    Eigen::Matrix3d* position_cov) {
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  Matrix6d information = Matrix6d::Zero();
  const Pose cam_from_world = world_from_cam.inverse();
  const Eigen::Matrix3d R_wc = world_from_cam.linear();
  int used = 0;
  for (const Eigen::Vector3d& b : body_points) {
    const Eigen::Vector3d q = world_from_body.linear() * b;  // from the body origin, world axes
    const Eigen::Vector3d p_cam = cam_from_world * (world_from_body.translation() + q);
    Eigen::Vector3d x;
    if (!camera.Project(p_cam, &x) || !(x(0) - x(2) > 0)) continue;
    const Eigen::Matrix3d cov = R_wc * camera.PointCovariance(x, pixel_cov) * R_wc.transpose();
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>() = -Skew(q);
    J.rightCols<3>() = Eigen::Matrix3d::Identity();
    information += J.transpose() * cov.ldlt().solve(J);
    ++used;
  }
  if (used < 3) return false;
  // A tiny prior keeps a degenerate set (collinear points: no roll about their line)
  // invertible; its covariance there is then huge, as it should be.
  information += 1e-9 * Matrix6d::Identity();
  const Matrix6d covariance = information.ldlt().solve(Matrix6d::Identity());
  *rotation_cov = covariance.topLeftCorner<3, 3>();
  *position_cov = covariance.bottomRightCorner<3, 3>();
  return true;
}

// The windows' positions of the body at one frame fused robustly: their medoid (the one
// nearest all others), so the estimate of a window that misplaced the body does not move it.
Eigen::Vector3d MedoidPosition(const std::vector<MapCluster::WindowPose>& poses) {
  return poses[MedoidIndex(0, poses.size(), [&](size_t i, size_t j) {
           return (poses[i].world_from_cluster.translation() - poses[j].world_from_cluster.translation()).norm();
         })].world_from_cluster.translation();
}

// The body's turn from frame a to frame b (world, left): the medoid of the turns of the window
// clusters that placed it at both. Within one bundle adjustment a far body's motion is
// consistent even where its orientation is not (a 40 m car's heading differed by up to 180°
// between windows that agreed on its turn), and the turn does not depend on the frame a window
// was aligned to the map in. None when no window saw both.
std::optional<Eigen::Matrix3d> MedoidTurn(const std::vector<MapCluster::WindowPose>& a,
                                          const std::vector<MapCluster::WindowPose>& b) {
  std::vector<Eigen::Matrix3d> turns;
  for (const MapCluster::WindowPose& pa : a)
    for (const MapCluster::WindowPose& pb : b)
      if (pa.source == pb.source)
        turns.push_back(pb.world_from_cluster.linear() * pa.world_from_cluster.linear().transpose());
  if (turns.empty()) return std::nullopt;
  return turns[MedoidIndex(0, turns.size(), [&](size_t i, size_t j) {
    return RotationAngle(turns[i].transpose() * turns[j]);
  })];
}

}  // namespace

std::map<int, ObjectTrack> MakeObjectTracks(MapState* map, const TrackletTable& table,
                                            const StereoCamera& camera,
                                            const std::vector<double>& timestamps,
                                            double frame_period_s,
                                            const ObjectTrackOptions& options) {
  std::map<int, std::vector<int>> members;
  for (int l : map->Landmarks())
    if (const int c = map->ClusterOf(l); c >= 1 && map->clusters().count(c)) members[c].push_back(l);
  const auto time_of = [&](int f) {
    return f < static_cast<int>(timestamps.size()) ? timestamps[f] : f * frame_period_s;
  };
  const Eigen::Matrix3d pixel_cov = options.pixel_sigma * options.pixel_sigma * Eigen::Matrix3d::Identity();
  std::map<int, ObjectTrack> tracks;
  std::vector<int> ids;
  for (const auto& [id, c] : map->clusters()) ids.push_back(id);
  for (int id : ids) {
    const MapCluster& cluster = map->clusters().at(id);
    const auto m = members.find(id);
    if (cluster.world_from_cluster.empty() || m == members.end()) continue;
    // The body frame: origin at the landmarks' centroid, axes the world's at the first frame.
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int l : m->second) centroid += *map->PositionInCluster(l);
    centroid /= static_cast<double>(m->second.size());
    Pose cluster_from_body = Pose::Identity();
    cluster_from_body.linear() = cluster.world_from_cluster.begin()->second.linear().transpose();
    cluster_from_body.translation() = centroid;
    map->ReframeCluster(id, cluster_from_body);
    if (!options.smooth) continue;

    // Landmarks seen at each frame, by their tracks' spans.
    std::map<int, std::vector<int>> starts, ends;
    for (int l : m->second) {
      if (l >= table.num_landmarks()) continue;
      const LandmarkSpan& span = table.Span(l);
      if (span.first_frame < 0) continue;
      starts[span.first_frame].push_back(l);
      ends[span.last_frame + 1].push_back(l);
    }
    std::map<int, Eigen::Vector3d> seen;  // landmark → position in the body frame
    auto start = starts.begin();
    auto end = ends.begin();
    std::vector<TrackMeasurement> measurements;
    std::map<int, std::vector<Eigen::Vector3d>> points_at;  // frame → landmarks seen, body frame
    // `cluster` is still the element ReframeCluster changed in place.
    for (const auto& [f, pose] : cluster.world_from_cluster) {
      for (; start != starts.end() && start->first <= f; ++start)
        for (int l : start->second) seen[l] = *map->PositionInCluster(l);
      for (; end != ends.end() && end->first <= f; ++end)
        for (int l : end->second) seen.erase(l);
      if (f >= map->num_frames() || !map->world_from_cam()[f]) continue;
      std::vector<Eigen::Vector3d> points;
      points.reserve(seen.size());
      for (const auto& [l, p] : seen) points.push_back(p);
      TrackMeasurement meas;
      meas.frame = f;
      meas.time_s = time_of(f);
      // The position from the windows' places of the body at f; the rotation chained from
      // the first frame (the world's axes) by the windows' turns between measured frames.
      const auto window = cluster.window_poses.find(f);
      const bool windowed = window != cluster.window_poses.end() && !window->second.empty();
      meas.world_from_body.translation() = windowed ? MedoidPosition(window->second) : pose.translation();
      if (measurements.empty()) {
        meas.world_from_body.linear() = pose.linear();
      } else {
        const auto before = cluster.window_poses.find(measurements.back().frame);
        if (windowed && before != cluster.window_poses.end())
          meas.turn = MedoidTurn(before->second, window->second);
        meas.world_from_body.linear() =
            meas.turn.value_or(Eigen::Matrix3d::Identity()) * measurements.back().world_from_body.linear();
      }
      if (!PoseCovariance(points, meas.world_from_body, *map->world_from_cam()[f], camera, pixel_cov,
                          &meas.rotation_cov, &meas.position_cov))
        continue;
      measurements.push_back(meas);
      points_at[f] = std::move(points);
    }
    if (measurements.empty()) continue;
    const auto covariance = [&](int f, const Pose& world_from_body, Eigen::Matrix3d* rotation_cov,
                                Eigen::Matrix3d* position_cov) {
      return PoseCovariance(points_at.at(f), world_from_body, *map->world_from_cam()[f], camera,
                            pixel_cov, rotation_cov, position_cov);
    };
    const SmoothedTrack smoothed =
        SmoothTrack(measurements, frame_period_s, options.smoother, covariance);
    if (auto log = GetLogger("system"); log->should_log(spdlog::level::debug)) {
      std::vector<double> sr, sp;
      for (const TrackMeasurement& meas : measurements) {
        sr.push_back(std::sqrt(meas.rotation_cov.trace() / 3) * 180 / M_PI);
        sp.push_back(std::sqrt(meas.position_cov.trace() / 3));
      }
      std::sort(sr.begin(), sr.end());
      std::sort(sp.begin(), sp.end());
      log->debug("object {} track: {} measured frames, median 1-sigma rotation {:.2f} deg x {:.1f}, "
                 "position {:.3f} m x {:.1f}; refused {} positions, {} rotations",
                 id, measurements.size(), sr[sr.size() / 2], std::sqrt(smoothed.rotation_scale),
                 sp[sp.size() / 2], std::sqrt(smoothed.position_scale), smoothed.rejected_positions,
                 smoothed.rejected_rotations);
    }
    ObjectTrack& track = tracks[id];
    track.states = smoothed.states;
    track.measurements = static_cast<int>(measurements.size());
    track.rejected_positions = smoothed.rejected_positions;
    track.rejected_rotations = smoothed.rejected_rotations;
    std::map<int, Pose> poses;
    for (const TrackState& s : smoothed.states) poses[s.frame] = s.world_from_body;
    map->SetTrajectory(id, std::move(poses));
  }
  return tracks;
}

}  // namespace cslam
