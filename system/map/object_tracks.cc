#include "system/map/object_tracks.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <Eigen/Geometry>
#include <functional>
#include <optional>
#include <set>

#include "core/logging.h"
#include "system/map/medoid.h"
#include "system/map/object_adjustment.h"
#include "system/map/observed_position.h"

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
                    const Eigen::Matrix3d& pixel_cov, bool free_scale,
                    Eigen::Matrix3d* rotation_cov, Eigen::Matrix3d* position_cov) {
  using Matrix7d = Eigen::Matrix<double, 7, 7>;
  Matrix7d information = Matrix7d::Zero();
  const Pose cam_from_world = world_from_cam.inverse();
  const Eigen::Matrix3d R_wc = world_from_cam.linear();
  int used = 0;
  for (const Eigen::Vector3d& b : body_points) {
    const Eigen::Vector3d q = world_from_body.linear() * b;  // from the body origin, world axes
    const Eigen::Vector3d p_cam = cam_from_world * (world_from_body.translation() + q);
    Eigen::Vector3d x;
    if (!camera.Project(p_cam, &x) || !(x(0) - x(2) > 0)) continue;
    const Eigen::Matrix3d cov = R_wc * camera.PointCovariance(x, pixel_cov) * R_wc.transpose();
    Eigen::Matrix<double, 3, 7> J;
    J.leftCols<3>() = -Skew(q);
    J.middleCols<3>(3) = Eigen::Matrix3d::Identity();
    J.col(6) = q;  // the scale of the body's shape (system/map/observed_position.h)
    information += J.transpose() * cov.ldlt().solve(J);
    ++used;
  }
  if (used < 3) return false;
  // A tiny prior keeps a degenerate set (collinear points: no roll about their line)
  // invertible; its covariance there is then huge, as it should be.
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  Matrix6d pose_information = information.topLeftCorner<6, 6>();
  // With the scale free, the body's apparent size no longer measures its depth: its
  // information is what is left once the scale is marginalised (Schur complement).
  if (free_scale && information(6, 6) > 0)
    pose_information -= information.topRightCorner<6, 1>() * information.bottomLeftCorner<1, 6>() /
                        information(6, 6);
  pose_information += 1e-9 * Matrix6d::Identity();
  const Matrix6d covariance = pose_information.ldlt().solve(Matrix6d::Identity());
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


// A frame's body pose from its keypoints, the position's covariance, and the places in the body
// of the landmarks it used.
struct KeypointPose {
  Pose world_from_body = Pose::Identity();
  Eigen::Matrix3d position_cov = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> points;
};

// Where the body's own keypoints put it and turn it, started from the windows' idea of its
// axes, a quarter, half and three-quarter turn of them about the world's vertical (a far car's
// windows flip its heading) and the axes the previous frame's keypoints gave.
std::optional<KeypointPose> PlaceByKeypoints(const std::vector<BodyKeypoint>& keypoints,
                                             const Eigen::Matrix3d& window_axes,
                                             const std::optional<Eigen::Matrix3d>& previous_axes,
                                             const Pose& world_from_cam, const StereoCamera& camera) {
  std::vector<Eigen::Matrix3d> starts;
  for (int quarter = 0; quarter < 4; ++quarter)
    starts.push_back(Eigen::AngleAxisd(quarter * M_PI / 2, Eigen::Vector3d::UnitY()) * window_axes);
  if (previous_axes) starts.push_back(*previous_axes);
  const auto pose = ObserveBodyPose(keypoints, starts, world_from_cam, camera);
  if (!pose) return std::nullopt;
  KeypointPose out{pose->world_from_body, pose->position_cov, {}};
  out.points.reserve(keypoints.size());
  for (const BodyKeypoint& k : keypoints) out.points.push_back(k.in_body);
  return out;
}

// Whether the keypoints make the body's places: where they place it at most frames and refuse
// the windows' places at most of those (the squared Mahalanobis distance between the two, under
// both covariances, above the smoother's gate). A window whose cluster took in another car's
// points, or that misjudged a far body's shape, puts it metres from where its keypoints are.
bool KeypointsLead(const std::vector<TrackMeasurement>& measurements,
                   const std::vector<std::optional<KeypointPose>>& by_keypoints, double gate_chi2) {
  std::vector<double> refusals;
  for (size_t i = 0; i < measurements.size(); ++i) {
    if (!by_keypoints[i]) continue;
    const Eigen::Vector3d gap =
        measurements[i].world_from_body.translation() - by_keypoints[i]->world_from_body.translation();
    refusals.push_back(
        gap.dot((by_keypoints[i]->position_cov + measurements[i].position_cov).ldlt().solve(gap)));
  }
  if (refusals.empty() || 2 * refusals.size() < measurements.size()) return false;
  const auto mid = refusals.begin() + static_cast<std::ptrdiff_t>(refusals.size() / 2);
  std::nth_element(refusals.begin(), mid, refusals.end());
  return *mid > gate_chi2;
}

// The keypoints' places replace the windows'; the windows keep the turns, which a bundle
// adjustment measures far better than one frame's keypoints do. The axes at the first frame
// become the medoid of those each placed frame gives when carried back through the turns, so
// the body's landmarks sit where its keypoints saw them.
void UseKeypointPlaces(const std::vector<std::optional<KeypointPose>>& by_keypoints,
                       std::vector<TrackMeasurement>* measurements) {
  const Eigen::Matrix3d first = measurements->front().world_from_body.linear();
  std::vector<Eigen::Matrix3d> anchors;
  for (size_t i = 0; i < measurements->size(); ++i) {
    if (!by_keypoints[i]) continue;
    TrackMeasurement& meas = (*measurements)[i];
    anchors.push_back(first * meas.world_from_body.linear().transpose() *
                      by_keypoints[i]->world_from_body.linear());
    meas.world_from_body.translation() = by_keypoints[i]->world_from_body.translation();
  }
  const Eigen::Matrix3d anchor = anchors[MedoidIndex(0, anchors.size(), [&](size_t a, size_t b) {
    return RotationAngle(anchors[a].transpose() * anchors[b]);
  })];
  for (TrackMeasurement& meas : *measurements)
    meas.world_from_body.linear() = meas.world_from_body.linear() * first.transpose() * anchor;
}


// The object adjustment (system/map/object_adjustment.h) on the smoothed track: poses and the
// landmarks' places refitted to the kept keypoints under the motion model. Its inputs are read
// from the map first and its results written back after, so that the objects' fits, which
// share nothing, can run side by side.
struct PendingAdjustment {
  int id = 0;
  std::vector<int> members;
  std::vector<ObjectTurn> turns;
  std::vector<Eigen::Vector3d> places;  // per member, in the body frame
  std::vector<ObjectKeypoint> keypoints;
  std::map<int, Pose> poses;
  ObjectAdjustment result;
  bool keypoints_lead = false;
};

PendingAdjustment PrepareAdjustment(int id, const std::vector<int>& members,
                                    std::vector<ObjectTurn> turns, const MapState& map,
                                    const ObjectTrack& track) {
  PendingAdjustment out;
  out.id = id;
  out.members = members;
  out.turns = std::move(turns);
  for (int l : members) {
    const int index = static_cast<int>(out.places.size());
    out.places.push_back(*map.PositionInCluster(l));
    for (const StereoObservation& o : map.object_observations().Of(l))
      if (!o.clipped) out.keypoints.push_back({o.frame, index, o.x, o.cov});
  }
  for (const TrackState& s : track.states) out.poses[s.frame] = s.world_from_body;
  return out;
}

// Writes a kept fit into the map and the track. The body frame's origin goes back to the
// landmarks' centroid; velocities follow the adjusted positions. Returns the frames adjusted.
int ApplyAdjustment(const PendingAdjustment& pending, MapState* map, ObjectTrack* track) {
  const ObjectAdjustment& adjusted = pending.result;
  if (auto log = GetLogger("system"); log->should_log(spdlog::level::debug)) {
    std::set<int> with_keypoints;
    for (const ObjectKeypoint& k : pending.keypoints) with_keypoints.insert(k.landmark);
    log->debug(
        "object {} adjustment: {} of {} keypoints explained, covariances x{:.2f}: {}", pending.id,
        adjusted.inliers, pending.keypoints.size(), adjusted.keypoint_scale,
        adjusted.adjusted
            ? fmt::format("kept, {} frames adjusted in {} stretches, {} of {} landmarks with keypoints fit",
                          adjusted.frames, adjusted.stretches,
                          std::count(adjusted.explained.begin(), adjusted.explained.end(), true),
                          with_keypoints.size())
        : adjusted.implausible
            ? fmt::format("refused, at frame {} it {} {:.2f} {} (the motion model's bound: {:.2f})",
                          adjusted.implausible_frame,
                          adjusted.implausible_turn ? "turns the body by" : "changes its velocity by",
                          adjusted.implausible_value, adjusted.implausible_turn ? "rad" : "m/s",
                          adjusted.implausible_bound)
            : std::string("refused"));
  }
  if (!adjusted.adjusted) return 0;
  const std::vector<Eigen::Vector3d>& places = pending.places;
  // The origin at the centroid of the places the fit explains: one far static point taken in
  // by a window would otherwise carry it metres off the body.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  int explained = 0;
  for (size_t i = 0; i < places.size(); ++i)
    if (adjusted.explained[i]) {
      centroid += places[i];
      ++explained;
    }
  if (explained > 0) centroid /= explained;
  for (size_t i = 0; i < pending.members.size(); ++i)
    map->SetPositionInCluster(pending.members[i], places[i] - centroid);
  Pose to_centroid = Pose::Identity();
  to_centroid.translation() = centroid;
  std::vector<TrackState>& states = track->states;
  for (TrackState& s : states) s.world_from_body = pending.poses.at(s.frame) * to_centroid;
  for (size_t k = 0; k < states.size(); ++k) {
    const size_t a = k > 0 && states[k - 1].frame == states[k].frame - 1 ? k - 1 : k;
    const size_t b = k + 1 < states.size() && states[k + 1].frame == states[k].frame + 1 ? k + 1 : k;
    if (a == b) continue;
    states[k].velocity = (states[b].world_from_body.translation() - states[a].world_from_body.translation()) /
                         (states[b].time_s - states[a].time_s);
  }
  return adjusted.frames;
}

// What is left once a track is final: the map's trajectory, and the body frame turned back to
// the world's axes at its first frame where the keypoints turned it.
void FinishTrack(int id, bool keypoints_lead, MapState* map, ObjectTrack* track) {
  std::map<int, Pose> poses;
  for (const TrackState& s : track->states) poses[s.frame] = s.world_from_body;
  map->SetTrajectory(id, std::move(poses));
  if (keypoints_lead && !track->states.empty()) {
    Pose turn_back = Pose::Identity();
    turn_back.linear() = track->states.front().world_from_body.linear().transpose();
    map->ReframeCluster(id, turn_back);
    for (TrackState& s : track->states) s.world_from_body = s.world_from_body * turn_back;
  }
}

}  // namespace

namespace {

// Tracks the moving clusters `ids` of `map` into `tracks` (see MakeObjectTracks).
void TrackObjects(const std::vector<int>& ids, MapState* map, const TrackletTable& table,
                  const StereoCamera& camera, const std::vector<double>& timestamps,
                  double frame_period_s, const ObjectTrackOptions& options,
                  const TaskRunner* runner, std::map<int, ObjectTrack>* tracks_out) {
  std::map<int, ObjectTrack>& tracks = *tracks_out;
  std::vector<PendingAdjustment> pending;
  std::map<int, std::vector<int>> members;
  for (int l : map->Landmarks())
    if (const int c = map->ClusterOf(l); c >= 1 && map->clusters().count(c)) members[c].push_back(l);
  const std::function<double(int)> time_of = [&](int f) {
    return f < static_cast<int>(timestamps.size()) ? timestamps[f] : f * frame_period_s;
  };
  const Eigen::Matrix3d pixel_cov = options.pixel_sigma * options.pixel_sigma * Eigen::Matrix3d::Identity();
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
    // Each frame's kept keypoints of the body's landmarks, with their places in the body.
    std::map<int, std::vector<BodyKeypoint>> keypoints_at;
    for (int l : m->second) {
      const Eigen::Vector3d in_body = *map->PositionInCluster(l);
      for (const StereoObservation& o : map->object_observations().Of(l))
        if (!o.clipped) keypoints_at[o.frame].push_back({in_body, o.x, o.cov});
    }
    std::map<int, Eigen::Vector3d> seen;  // landmark → position in the body frame
    auto start = starts.begin();
    auto end = ends.begin();
    std::vector<TrackMeasurement> measurements;
    std::vector<std::optional<KeypointPose>> by_keypoints;  // per measurement
    std::map<int, std::vector<Eigen::Vector3d>> points_at;  // frame → landmarks seen, body frame
    std::optional<Eigen::Matrix3d> last_keypoint_axes;
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
                          false, &meas.rotation_cov, &meas.position_cov))
        continue;
      std::optional<KeypointPose> placed;
      if (const auto k = keypoints_at.find(f); k != keypoints_at.end())
        placed = PlaceByKeypoints(k->second, meas.world_from_body.linear(), last_keypoint_axes,
                                  *map->world_from_cam()[f], camera);
      if (placed) last_keypoint_axes = placed->world_from_body.linear();
      measurements.push_back(meas);
      by_keypoints.push_back(std::move(placed));
      points_at[f] = std::move(points);
    }
    if (measurements.empty()) continue;
    const bool keypoints_lead = KeypointsLead(measurements, by_keypoints, options.smoother.gate_chi2);
    std::set<int> placed_frames;
    if (keypoints_lead) {
      UseKeypointPlaces(by_keypoints, &measurements);
      for (size_t i = 0; i < measurements.size(); ++i) {
        if (!by_keypoints[i]) continue;
        placed_frames.insert(measurements[i].frame);
        points_at[measurements[i].frame] = std::move(by_keypoints[i]->points);
      }
    }
    const auto covariance = [&](int f, const Pose& world_from_body, Eigen::Matrix3d* rotation_cov,
                                Eigen::Matrix3d* position_cov) {
      if (!PoseCovariance(points_at.at(f), world_from_body, *map->world_from_cam()[f], camera,
                          pixel_cov, keypoints_lead, rotation_cov, position_cov))
        return false;
      // A frame the keypoints did not place keeps the windows' turn but not their place.
      if (keypoints_lead && !placed_frames.count(f)) *position_cov = 1e6 * Eigen::Matrix3d::Identity();
      return true;
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
      log->debug("object {} track: places from {} ({} of {} frames placed by keypoints), {} measured frames, median 1-sigma rotation {:.2f} deg x {:.1f}, "
                 "position {:.3f} m x {:.1f}; refused {} positions, {} rotations",
                 id, keypoints_lead ? "keypoints" : "windows", placed_frames.size(),
                 keypoints_at.size(), measurements.size(), sr[sr.size() / 2], std::sqrt(smoothed.rotation_scale),
                 sp[sp.size() / 2], std::sqrt(smoothed.position_scale), smoothed.rejected_positions,
                 smoothed.rejected_rotations);
    }
    ObjectTrack& track = tracks[id];
    track.states = smoothed.states;
    track.measurements = static_cast<int>(measurements.size());
    track.rejected_positions = smoothed.rejected_positions;
    track.rejected_rotations = smoothed.rejected_rotations;
    if (options.adjust) {
      // The windows' turns, at the covariances the smoother found them to have.
      std::vector<ObjectTurn> turns;
      for (size_t i = 1; i < measurements.size(); ++i) {
        if (!measurements[i].turn) continue;
        Eigen::Matrix3d a, b, p;
        if (!covariance(measurements[i - 1].frame, measurements[i - 1].world_from_body, &a, &p) ||
            !covariance(measurements[i].frame, measurements[i].world_from_body, &b, &p))
          continue;
        turns.push_back({measurements[i - 1].frame, measurements[i].frame, *measurements[i].turn,
                         smoothed.rotation_scale * (a + b)});
      }
      pending.push_back(PrepareAdjustment(id, m->second, std::move(turns), *map, track));
      pending.back().keypoints_lead = keypoints_lead;
      continue;
    }
    FinishTrack(id, keypoints_lead, map, &track);
  }
  // The objects' fits share nothing: side by side on the runner's threads. Each reads only its
  // own inputs and the map's camera poses, which nothing writes meanwhile.
  const std::vector<std::optional<Pose>>& world_from_cam = map->world_from_cam();
  RunTasks(runner, static_cast<int>(pending.size()), [&](int i) {
    PendingAdjustment& p = pending[i];
    p.result = AdjustObject(p.keypoints, p.turns, &p.places, &p.poses, world_from_cam, camera,
                            time_of, options.smoother, runner);
  });
  for (const PendingAdjustment& p : pending) {
    ObjectTrack& track = tracks.at(p.id);
    track.adjusted_frames = ApplyAdjustment(p, map, &track);
    FinishTrack(p.id, p.keypoints_lead, map, &track);
  }
}

}  // namespace

std::map<int, ObjectTrack> MakeObjectTracks(MapState* map, const TrackletTable& table,
                                            const StereoCamera& camera,
                                            const std::vector<double>& timestamps,
                                            double frame_period_s,
                                            const ObjectTrackOptions& options,
                                            const TaskRunner* runner) {
  std::map<int, ObjectTrack> tracks;
  std::vector<int> ids;
  for (const auto& [id, c] : map->clusters()) ids.push_back(id);
  TrackObjects(ids, map, table, camera, timestamps, frame_period_s, options, runner, &tracks);
  if (!options.smooth) return tracks;
  std::set<int> again;
  const auto retrack = [&](const std::vector<std::pair<int, int>>& merged) {
    for (const auto& [kept, gone] : merged) {
      again.erase(gone);
      tracks.erase(gone);
      again.insert(kept);
    }
  };
  if (options.merge_co_located) {
    // Each track's typical position error: the median of its states' per-axis 1 σ.
    std::map<int, double> sigma;
    for (const auto& [id, track] : tracks) {
      std::vector<double> s;
      for (const TrackState& state : track.states) s.push_back(std::sqrt(state.position_cov.trace() / 3));
      if (s.empty()) continue;
      std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
      sigma[id] = s[s.size() / 2];
    }
    retrack(map->MergeCoLocatedClusters([&sigma](int id) {
      const auto it = sigma.find(id);
      return it == sigma.end() ? 0.0 : it->second;
    }));
  }
  ReappearanceGate gate;
  gate.frame_period_s = frame_period_s;
  gate.max_gap_s = options.join_max_gap_s;
  gate.max_acceleration_mps2 = options.join_max_acceleration_mps2;
  retrack(map->MergeReappearedClusters(gate));
  if (again.empty()) return tracks;
  for (int id : again) tracks.erase(id);
  TrackObjects({again.begin(), again.end()}, map, table, camera, timestamps, frame_period_s,
               options, runner, &tracks);
  return tracks;
}

}  // namespace cslam
