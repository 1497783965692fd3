#include "system/run/run_metrics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>

#include "core/logging.h"
#include "system/eval/box_labels.h"
#include "system/eval/clustering_metrics.h"
#include "system/eval/noise_check.h"
#include "system/eval/object_camera_frame_error.h"
#include "system/eval/object_motion_error.h"
#include "system/eval/trajectory_evaluation.h"
#include "system/runtime/resource_log.h"
#include "system/synthetic/synthetic_image_io.h"
#include "system/synthetic_images/synthetic_landmark_truth.h"

namespace cslam {

namespace {

// A landmark tracked for fewer frames cannot have a valid motion distance (spec §3), so no
// method can cluster it; clustering metrics are over the landmarks that can be clustered.
constexpr int kMinObservationsToCluster = 4;

std::vector<int> ClusterableLandmarks(const TrackletTable& table) {
  std::vector<int> ids;
  for (int l = 0; l < table.num_landmarks(); ++l)
    if (table.Span(l).observations >= kMinObservationsToCluster)
      ids.push_back(l);
  return ids;
}

Trajectory GroundTruthTrajectory(const std::vector<Pose>& poses, const std::vector<double>& times,
                                 int frames) {
  Trajectory t;
  for (int f = 0; f < frames && f < static_cast<int>(poses.size()); ++f) {
    t.frames.push_back(f);
    t.poses.push_back(poses[f]);
    t.timestamps.push_back(f < static_cast<int>(times.size()) ? times[f] : 0.1 * f);
  }
  return t;
}

// The map's camera pose at `frame`, or nullopt.
std::optional<Pose> CameraAt(const MapState& map, int frame) {
  if (frame < 0 || frame >= map.num_frames()) return std::nullopt;
  return map.world_from_cam()[frame];
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// An object's motion errors, into `po` (nothing with no consecutive frames).
void FillMotionError(const std::vector<ObjectFramePoses>& frames, RunMetrics::PerObject* po) {
  const ObjectMotionError e = ComputeObjectMotionError(frames);
  if (e.pairs == 0) return;
  po->me_r_deg = e.me_r_deg;
  po->me_t_m = e.me_t_m;
  po->me_max_r_deg = e.max_r_deg;
  po->me_pairs = e.pairs;
}

// The largest frame-to-frame rotation of any reported object (no ground truth needed).
void FillLargestRotation(const RunTrajectories& trajectories, const MapState& map, RunMetrics* m) {
  for (const auto& [id, c] : map.clusters()) {
    const auto t = trajectories.clusters.find(id);
    if (t == trajectories.clusters.end()) continue;
    const auto r = LargestFrameToFrameRotation(t->second.frames, t->second.poses);
    if (!r || (m->objects.max_frame_rotation_deg && r->deg <= *m->objects.max_frame_rotation_deg))
      continue;
    m->objects.max_frame_rotation_deg = r->deg;
    m->objects.max_frame_rotation_object = id;
    m->objects.max_frame_rotation_frame = r->frame;
  }
}

void FillClustering(const std::vector<int>& truth, const std::vector<int>& predicted,
                    RunMetrics* m) {
  if (truth.empty()) return;
  m->clustering.accuracy = ClusteringAccuracy(truth, predicted);
  m->clustering.vi = VariationOfInformation(truth, predicted);
  std::vector<int> t = truth, p;
  for (int x : predicted)
    if (x >= 0) p.push_back(x);
  std::sort(t.begin(), t.end());
  std::sort(p.begin(), p.end());
  m->clustering.gt_objects = static_cast<int>(std::unique(t.begin(), t.end()) - t.begin());
  m->clustering.clusters = static_cast<int>(std::unique(p.begin(), p.end()) - p.begin());
}

// Reported objects against labels (truth 0 = on no moving object): how many of them lie
// mostly on one moving object, and how much of the static world sits in one.
void FillObjectPrecision(const std::vector<int>& truth, const std::vector<int>& predicted,
                         RunMetrics* m) {
  std::map<int, std::map<int, int>> by_cluster;  // predicted moving cluster → truth → count
  long long statics = 0, static_in_objects = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (predicted[i] >= 1) ++by_cluster[predicted[i]][truth[i]];
    if (truth[i] == 0) {
      ++statics;
      static_in_objects += predicted[i] >= 1;
    }
  }
  int on_movers = 0;
  for (const auto& [cluster, counts] : by_cluster) {
    int total = 0, best = 0;
    for (const auto& [t, n] : counts) {
      total += n;
      if (t >= 1) best = std::max(best, n);
    }
    on_movers += 2 * best > total;
    std::string labels;
    for (const auto& [t, n] : counts) labels += fmt::format(" {}:{}", t, n);
    GetLogger("system")->debug("reported object {}: landmarks by label (0 static):{}", cluster,
                               labels);
  }
  m->objects.reported_on_movers = on_movers;
  if (m->objects.reported && *m->objects.reported > 0)
    m->objects.precision = static_cast<double>(on_movers) / *m->objects.reported;
  if (statics > 0)
    m->objects.static_in_objects_fraction = static_cast<double>(static_in_objects) / statics;
}

// For each ground-truth object (label >= 1), the predicted moving cluster matched to it by
// the Hungarian matching, when that cluster holds at least half of the object's landmarks.
std::map<int, int> FoundClusters(const std::vector<int>& truth, const std::vector<int>& predicted) {
  std::map<int, int> object_size, found;
  for (int t : truth) ++object_size[t];
  for (const auto& [t, p] : MatchClusters(truth, predicted)) {
    if (t < 1 || p < 1) continue;
    int shared = 0;
    for (size_t i = 0; i < truth.size(); ++i) shared += truth[i] == t && predicted[i] == p;
    if (2 * shared >= object_size[t]) found[t] = p;
  }
  return found;
}

void SyntheticMetrics(const RunInput& input, const PipelineResult& result,
                      const RunTrajectories& trajectories, RunMetrics* m) {
  const SyntheticSequence& seq = *input.synthetic;
  const MapState& map = result.map;
  const TrackletTable& table = result.table;
  // Replayed tracklets are all in the input, even when the online run released its copy.
  const TrackletTable& all_observations = input.observations ? *input.observations : table;
  // Replayed tracklets share the generator's landmark ids; a frontend's landmarks on rendered
  // images are labelled by the object-id image under their first keypoint.
  LandmarkTruth lm_truth;
  if (input.kind == InputKind::kSynthetic) {
    lm_truth.object = seq.landmark_object;
    lm_truth.in_object = seq.landmark_in_object;
  } else if (input.kind == InputKind::kSyntheticImages) {
    lm_truth = LabelLandmarksByIdImages(
        table, seq, [&](int frame) {
          return ReadObjectIdImage(input.synthetic_dir.empty() ? input.path : input.synthetic_dir, frame);
        });
  } else {
    return;
  }
  std::vector<int> ids;
  for (int l : ClusterableLandmarks(table))
    if (l < static_cast<int>(lm_truth.object.size()) && lm_truth.object[l] >= 0) ids.push_back(l);
  std::vector<int> truth, predicted;
  for (int l : ids) {
    truth.push_back(lm_truth.object[l]);
    predicted.push_back(map.ClusterOf(l));
  }
  FillClustering(truth, predicted, m);
  FillObjectPrecision(truth, predicted, m);

  const std::map<int, int> found = FoundClusters(truth, predicted);
  for (int obj = 1; obj < seq.num_objects(); ++obj) {
    const int n_obj = static_cast<int>(std::count(truth.begin(), truth.end(), obj));
    if (n_obj == 0) continue;  // never observed well enough: not part of this sequence's task
    RunMetrics::PerObject po;
    po.gt_object = obj;
    po.landmarks = n_obj;
    const auto it = found.find(obj);
    const auto cluster = it == found.end() ? map.clusters().end() : map.clusters().find(it->second);
    if (cluster != map.clusters().end() && cluster->second.world_from_cluster.size() >= 2) {
      // Express the cluster's trajectory in the object's own body frame (the cluster frame's
      // origin is arbitrary), using the landmarks that truly belong to the object.
      std::vector<Eigen::Vector3d> src, dst;
      for (size_t k = 0; k < ids.size(); ++k)
        if (truth[k] == obj && predicted[k] == it->second) {
          src.push_back(*map.PositionInCluster(ids[k]));
          dst.push_back(lm_truth.in_object[ids[k]]);
        }
      const Pose object_from_cluster = AlignUmeyama(src, dst, false).rigid;
      Trajectory est = trajectories.clusters.at(it->second), gt;
      for (size_t k = 0; k < est.size(); ++k) {
        est.poses[k] = est.poses[k] * object_from_cluster.inverse();
        gt.frames.push_back(est.frames[k]);
        gt.timestamps.push_back(est.timestamps[k]);
        gt.poses.push_back(seq.world_from_object[obj][est.frames[k]]);
      }
      po = EvaluateObjectTrajectory(gt, est);
      po.gt_object = obj;
      po.landmarks = n_obj;
      po.cluster = it->second;
      // As on KITTI (below) the point's place on the object is fitted: the alignment above rests
      // on the estimated landmarks, whose depth errors move the origin along with them.
      std::vector<ObjectInCamera> seen;
      for (size_t k = 0; k < est.size(); ++k) {
        const int f = est.frames[k];
        const std::optional<Pose> cam = CameraAt(map, f);
        if (!cam || f >= static_cast<int>(seq.world_from_cam.size())) continue;
        seen.push_back({cam->inverse() * est.poses[k].translation(),
                        seq.world_from_cam[f].inverse() * seq.world_from_object[obj][f]});
      }
      po.camera_frame_rmse_m = Finite(ObjectErrorInCameraFrame(seen, true).rmse_m);
      std::vector<ObjectFramePoses> motion;
      for (size_t k = 0; k < est.size(); ++k) {
        const int f = est.frames[k];
        const std::optional<Pose> cam = CameraAt(map, f);
        if (!cam || f >= static_cast<int>(seq.world_from_cam.size())) continue;
        motion.push_back({f, est.poses[k], *cam, seq.world_from_object[obj][f], seq.world_from_cam[f]});
      }
      FillMotionError(motion, &po);
    }
    // Over the frames where any of its clusterable landmarks is seen.
    std::vector<char> seen_at(seq.world_from_cam.size(), 0);
    for (size_t k = 0; k < ids.size(); ++k)
      if (truth[k] == obj)
        for (const StereoObservation& o : all_observations.ObservationsOf(ids[k]))
          if (o.frame < static_cast<int>(seen_at.size())) seen_at[o.frame] = 1;
    std::vector<double> distances;
    for (size_t f = 0; f < seen_at.size() && f < seq.world_from_object[obj].size(); ++f)
      if (seen_at[f])
        distances.push_back(
            (seq.world_from_cam[f].inverse() * seq.world_from_object[obj][f].translation()).norm());
    po.median_distance_m = Finite(Median(distances));
    m->objects.per_object.push_back(po);
  }
  SummariseObjects(m->objects);

  double se = 0;
  long long n = 0;
  for (int l : ids) {
    for (const StereoObservation& o : all_observations.ObservationsOf(l)) {
      if (o.frame >= result.frames_processed) break;
      const auto p = map.WorldPosition(l, o.frame);
      if (!p) continue;
      se += (*p - seq.world_from_object[lm_truth.object[l]][o.frame] * lm_truth.in_object[l]).squaredNorm();
      ++n;
    }
  }
  if (n > 0) {
    m->landmarks.rmse_m = std::sqrt(se / n);
    m->landmarks.count = n;
  }
}

void KittiRawObjectMetrics(const RunInput& input, const PipelineResult& result,
                           const RunTrajectories& trajectories, RunMetrics* m) {
  if (input.gt_boxes.empty() || !input.gt_world_from_cam) return;
  const MapState& map = result.map;
  const std::vector<int> moving = MovingTrackIds(input.gt_boxes, *input.gt_world_from_cam);
  const std::vector<int> labels =
      LabelLandmarksByBoxes(result.table, input.camera, input.gt_boxes, moving);
  const std::vector<int> ids = ClusterableLandmarks(result.table);
  std::vector<int> truth, predicted;
  for (int l : ids) {
    truth.push_back(labels[l]);
    predicted.push_back(map.ClusterOf(l));
  }
  FillClustering(truth, predicted, m);
  FillObjectPrecision(truth, predicted, m);
  const std::map<int, int> found = FoundClusters(truth, predicted);
  for (size_t k = 0; k < moving.size(); ++k) {
    const int obj = static_cast<int>(k) + 1;
    RunMetrics::PerObject po;
    po.gt_object = moving[k];
    po.landmarks = static_cast<int>(std::count(truth.begin(), truth.end(), obj));
    const auto it = found.find(obj);
    const auto cluster = it == found.end() ? map.clusters().end() : map.clusters().find(it->second);
    if (cluster != map.clusters().end() && cluster->second.world_from_cluster.size() >= 2) {
      // Boxes have no trustworthy orientation at the landmark level: compare the box centre's
      // track with the track of the centroid of the cluster's landmarks on the object.
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      int n = 0;
      for (size_t i = 0; i < ids.size(); ++i)
        if (truth[i] == obj && predicted[i] == it->second) {
          centroid += *map.PositionInCluster(ids[i]);
          ++n;
        }
      centroid /= std::max(n, 1);
      std::map<int, Eigen::Vector3d> box_track;
      for (const auto& [f, p] : BoxCentreTrajectory(input.gt_boxes, *input.gt_world_from_cam, moving[k]))
        box_track[f] = p;
      const Trajectory& track = trajectories.clusters.at(it->second);
      std::vector<ObjectInCamera> seen;
      std::vector<ObjectFramePoses> motion;
      Trajectory gt, est;
      for (size_t i = 0; i < track.size(); ++i) {
        const auto b = box_track.find(track.frames[i]);
        if (b == box_track.end()) continue;
        Pose e = Pose::Identity(), g = Pose::Identity();
        e.translation() = track.poses[i] * centroid;
        g.translation() = b->second;
        est.frames.push_back(track.frames[i]);
        gt.frames.push_back(track.frames[i]);
        est.poses.push_back(e);
        gt.poses.push_back(g);
        est.timestamps.push_back(track.timestamps[i]);
        gt.timestamps.push_back(track.timestamps[i]);
        // As the camera sees it: the labels are boxes in that frame's camera, so neither the
        // GPS world nor the estimated camera's drift enters.
        const std::optional<Pose> cam = CameraAt(map, track.frames[i]);
        if (!cam) continue;
        for (const ObjectBox& box : input.gt_boxes[track.frames[i]])
          if (box.track_id == moving[k]) {
            const Pose cam_from_centre = box.cam_from_box * Eigen::Translation3d(0, 0, box.h / 2);
            seen.push_back({cam->inverse() * e.translation(), cam_from_centre});
            const Pose& gt_cam = (*input.gt_world_from_cam)[track.frames[i]];
            motion.push_back({track.frames[i], track.poses[i], *cam, gt_cam * cam_from_centre, gt_cam});
          }
      }
      if (gt.size() >= 2) {
        po = EvaluateObjectTrajectory(gt, est);
        // The landmarks' centroid is a point on the object, not its box's centre.
        const ObjectCameraFrameError in_camera = ObjectErrorInCameraFrame(seen, true);
        po.camera_frame_rmse_m = Finite(in_camera.rmse_m);
        GetLogger("system")->debug(
            "labelled object {}: camera-frame error {:.3f} m over {} frames, tracked point in its "
            "box at ({:.2f}, {:.2f}, {:.2f}) m",
            moving[k], in_camera.rmse_m, in_camera.frames, in_camera.point_in_object.x(),
            in_camera.point_in_object.y(), in_camera.point_in_object.z());
        FillMotionError(motion, &po);
        po.rpe_frame_r_rad.reset();  // positions only: rotations are not compared
        po.rpe_pairs_r_rad.reset();
        po.gt_object = moving[k];
        po.landmarks = static_cast<int>(std::count(truth.begin(), truth.end(), obj));
        po.cluster = it->second;
      }
    }
    std::vector<double> distances;
    for (int f = 0; f < result.frames_processed && f < static_cast<int>(input.gt_boxes.size()); ++f)
      for (const ObjectBox& box : input.gt_boxes[f])
        if (box.track_id == moving[k]) distances.push_back(box.cam_from_box.translation().norm());
    po.median_distance_m = Finite(Median(distances));
    m->objects.per_object.push_back(po);
  }
  SummariseObjects(m->objects);
}

// The ground truth's cross-check (RunMetrics::GroundTruthCheck) over the frames processed.
RunMetrics::GroundTruthCheck CheckGroundTruth(const RunInput& input, const PipelineResult& result,
                                              const Trajectory& camera_trajectory) {
  const GroundTruthCrossCheck& check = *input.gt_cross_check;
  RunMetrics::GroundTruthCheck g;
  g.cross_check = check.source;
  const int frames = std::min<int>(result.frames_processed, check.positions.size());
  if (!check.position_accuracy_m.empty())
    g.position_accuracy_median_m = Median(std::vector<double>(
        check.position_accuracy_m.begin(),
        check.position_accuracy_m.begin() + std::min<int>(frames, check.position_accuracy_m.size())));
  std::vector<Pose> poses;
  for (int f = 0; f < frames; ++f) {
    Pose p = Pose::Identity();
    p.translation() = check.positions[f];
    poses.push_back(p);
  }
  const Trajectory second = GroundTruthTrajectory(poses, input.timestamps, frames);
  const Trajectory gt = GroundTruthTrajectory(*input.gt_world_from_cam, input.timestamps, frames);
  g.cross_check_path_length_m = PathLength(second);
  g.cross_check_ate_sim3_m = Finite(ComputeAte(gt, second, true).rmse_m);
  const AteResult camera = ComputeAte(second, camera_trajectory, true);
  g.camera_ate_sim3_vs_cross_check_m = Finite(camera.rmse_m);
  if (g.camera_ate_sim3_vs_cross_check_m) g.camera_sim3_scale_vs_cross_check = camera.alignment.scale;
  return g;
}

}  // namespace

RunMetrics ComputeRunMetrics(const RunInput& input, const PipelineResult& result,
                             const RunTrajectories& trajectories, const PipelineOptions& options) {
  RunMetrics m;
  m.sequence = input.name;
  m.frames = result.frames_processed;
  m.method = NameOf(kMethodNames, options.method) +
             (options.ablation == ClusterSlamAblation::kNone
                  ? ""
                  : "/" + NameOf(kAblationNames, options.ablation)) +
             " (" + NameOf(kRunModeNames, options.mode) + ")";
  if (input.gt_world_from_cam && result.frames_processed > 1) {
    // Up to the last frame with an estimate: after a stop the frames read since the last
    // window have none, and the ground truth's path length must cover what the estimate does.
    const int estimated = trajectories.camera.frames.empty() ? result.frames_processed
                                                             : trajectories.camera.frames.back() + 1;
    const Trajectory gt = GroundTruthTrajectory(*input.gt_world_from_cam, input.timestamps,
                                                std::min(result.frames_processed, estimated));
    m.camera = EvaluateCameraTrajectory(gt, trajectories.camera);
  }
  if (input.gt_world_from_cam && input.gt_cross_check && result.frames_processed > 1)
    m.ground_truth = CheckGroundTruth(input, result, trajectories.camera);
  m.objects.reported = static_cast<int>(result.map.clusters().size());
  FillLargestRotation(trajectories, result.map, &m);
  if (input.synthetic) SyntheticMetrics(input, result, trajectories, &m);
  if (input.kind == InputKind::kKittiRaw) KittiRawObjectMetrics(input, result, trajectories, &m);
  if (m.objects.gt && *m.objects.gt > 0)
    m.objects.recall = static_cast<double>(m.objects.matched.value_or(0)) / *m.objects.gt;
  {
    const double offset = result.disparity_offset ? result.disparity_offset->applied_px : 0.0;
    const NoiseCheck noise = CheckStaticNoise(result.map, result.table, input.camera, offset);
    if (noise.landmarks > 0) {
      m.noise.static_chi2_per_dof = noise.chi2_per_dof;
      m.noise.static_cut_fraction = noise.cut_fraction;
      m.noise.static_landmarks = noise.landmarks;
      m.noise.static_observations = noise.observations;
    }
  }
  if (result.batch && result.batch->estimate.chi2 > 0)
    m.log_chi2 = std::log(result.batch->estimate.chi2);

  m.timing.total_s = result.total_s;
  if (result.total_s > 0) m.timing.hz = result.frames_processed / result.total_s;
  if (const double rss = PeakResidentMegabytes(); rss > 0) m.timing.peak_rss_mb = rss;
  if (!result.frontend_frames.empty()) {
    double sum = 0;
    for (const auto& f : result.frontend_frames) sum += f.total_ms;
    m.timing.frontend_ms_per_frame = sum / result.frontend_frames.size();
  }
  std::vector<double> backend_ms;
  for (const auto& w : result.windows) backend_ms.push_back(w.backend_ms);
  if (!backend_ms.empty()) m.timing.backend_ms_per_window = Median(backend_ms);
  m.run.interrupted = result.interrupted;
  m.run.windows = static_cast<int>(result.windows.size());
  for (const auto& w : result.windows)
    if (w.failed) m.run.failed_windows.push_back(w.range.begin);
  for (const auto& w : result.windows)
    if (w.adjustment_failed) m.run.adjustment_failed_windows.push_back(w.range.begin);
  for (const auto& f : result.frontend_frames)
    if (f.tracking_lost) m.run.tracking_lost.push_back(f.frame);
  m.run.gaps = result.map.gaps();
  if (const auto& d = result.disparity_offset) {
    m.calibration.disparity_offset_frames = d->frames.size();
    if (d->estimate.usable) {
      m.calibration.disparity_offset_px = d->estimate.offset_px;
      m.calibration.disparity_offset_sigma_px = d->estimate.sigma_px;
    }
    m.calibration.disparity_offset_applied_px = d->applied_px;
    if (std::isfinite(d->yaw_rate)) m.calibration.disparity_offset_yaw_rate = d->yaw_rate;
    m.calibration.disparity_offset_decision = d->decision;
  }
  return m;
}

std::string SummarizeMetrics(const RunMetrics& m) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << m.sequence << ": " << m.frames.value_or(0) << " frames, " << m.method;
  if (m.timing.total_s) s << ", " << *m.timing.total_s << " s";
  if (m.timing.hz) s << " (" << std::setprecision(1) << *m.timing.hz << " frames/s)" << std::setprecision(3);
  s << "\n";
  if (m.camera.ate_m) {
    s << "  camera: ATE " << *m.camera.ate_m << " m";
    if (m.camera.ate_sim3_m) s << " (Sim3 " << *m.camera.ate_sim3_m << " m, scale " << m.camera.sim3_scale.value_or(NAN) << ")";
    if (m.camera.rpe_frame_t_m) s << ", RPE/frame " << *m.camera.rpe_frame_t_m << " m " << m.camera.rpe_frame_r_rad.value_or(NAN) << " rad";
    if (m.camera.path_length_m) s << ", path " << *m.camera.path_length_m << " m (gt " << m.camera.gt_path_length_m.value_or(NAN) << " m)";
    s << "\n";
  }
  if (m.ground_truth.cross_check_ate_sim3_m)
    s << "  ground truth check: " << m.ground_truth.cross_check.value_or("?") << " lie "
      << *m.ground_truth.cross_check_ate_sim3_m << " m (Sim3 ATE) from the ground truth, whose"
      << " stated position accuracy is " << m.ground_truth.position_accuracy_median_m.value_or(NAN)
      << " m (median); the camera lies " << m.ground_truth.camera_ate_sim3_vs_cross_check_m.value_or(NAN)
      << " m from them\n";
  if (m.clustering.accuracy)
    s << "  clustering: accuracy " << *m.clustering.accuracy << ", VI " << m.clustering.vi.value_or(NAN)
      << " (natural log), " << m.clustering.clusters.value_or(0) << " clusters for "
      << m.clustering.gt_objects.value_or(0) << " true objects\n";
  if (m.objects.gt)
    s << "  objects: " << m.objects.matched.value_or(0) << " of " << *m.objects.gt << " found"
      << (m.objects.eligible ? " (" + std::to_string(m.objects.found_eligible.value_or(0)) + " of " +
                                   std::to_string(*m.objects.eligible) + " with >= " +
                                   std::to_string(m.objects.eligible_min_landmarks.value_or(0)) +
                                   " landmarks)"
                             : "")
      << (m.objects.ate_m ? ", mean ATE " + std::to_string(*m.objects.ate_m) + " m" : "")
      << (m.objects.camera_frame_rmse_m
              ? ", in the camera frame " + std::to_string(*m.objects.camera_frame_rmse_m) + " m"
              : "")
      << "\n";
  if (m.objects.me_r_deg) {
    s << "  object motion per frame: ME_r " << *m.objects.me_r_deg << " deg, ME_t "
      << m.objects.me_t_m.value_or(NAN) << " m (means over found objects)";
    for (const RunMetrics::DistanceBand& b : m.objects.distance_bands) {
      if (b.found == 0) continue;
      s << "; " << (b.to_m ? (b.from_m == 0 ? "<= " + std::to_string(int(*b.to_m)) + " m"
                                            : std::to_string(int(b.from_m)) + "-" +
                                                  std::to_string(int(*b.to_m)) + " m")
                           : "> " + std::to_string(int(b.from_m)) + " m")
        << ": " << b.found << " at " << b.me_r_deg.value_or(NAN) << " deg, "
        << b.me_t_m.value_or(NAN) << " m";
    }
    s << "\n";
  }
  if (m.objects.reported) {
    s << "  reported objects: " << *m.objects.reported;
    if (m.objects.precision)
      s << " (" << m.objects.reported_on_movers.value_or(0) << " on a moving object; static "
        << "landmarks in objects " << std::setprecision(2)
        << 100.0 * m.objects.static_in_objects_fraction.value_or(NAN) << " %)" << std::setprecision(3);
    if (m.objects.max_frame_rotation_deg)
      s << "; largest turn between frames " << *m.objects.max_frame_rotation_deg << " deg (object "
        << m.objects.max_frame_rotation_object.value_or(-1) << " at frame "
        << m.objects.max_frame_rotation_frame.value_or(-1) << ")";
    s << "\n";
  }
  if (m.noise.static_chi2_per_dof)
    s << "  noise: static residuals chi2/dof " << *m.noise.static_chi2_per_dof << " after cutting "
      << std::setprecision(2) << 100.0 * m.noise.static_cut_fraction.value_or(NAN)
      << " % of " << m.noise.static_observations.value_or(0) << " observations\n"
      << std::setprecision(3);
  if (m.landmarks.rmse_m) s << "  landmarks: RMSE " << *m.landmarks.rmse_m << " m over " << m.landmarks.count.value_or(0) << " observations\n";
  if (m.log_chi2) s << "  log chi2: " << *m.log_chi2 << "\n";
  auto list = [](const std::vector<int>& v) {
    std::string out;
    for (int x : v) out += (out.empty() ? "" : " ") + std::to_string(x);
    return out;
  };
  if (m.run.interrupted || !m.run.failed_windows.empty() || !m.run.tracking_lost.empty() || !m.run.gaps.empty()) {
    s << "  run: " << m.run.windows << " windows";
    if (m.run.interrupted) s << ", interrupted";
    if (!m.run.failed_windows.empty()) s << ", discarded windows from frames " << list(m.run.failed_windows);
    if (!m.run.tracking_lost.empty()) s << ", tracking lost at frames " << list(m.run.tracking_lost);
    if (!m.run.gaps.empty()) s << ", trajectory gaps at frames " << list(m.run.gaps);
    s << "\n";
  }
  return s.str();
}

}  // namespace cslam
