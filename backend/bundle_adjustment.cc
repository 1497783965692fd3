#include "backend/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/product_manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <functional>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>

#include "backend/ceres_solve.h"
#include "backend/reprojection_error.h"
#include "backend/stereo_lm.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/spd3.h"
#include "core/task_runner.h"
#include "core/timer.h"

namespace cslam {

using namespace ba_detail;

namespace {

/// Counts observations per pose block so that poorly observed poses can be held.
using ObservationCount = std::map<const PoseBlock*, int>;

void HoldWeakPoses(std::vector<PoseBlock>& poses, const ObservationCount& counts, int min_count,
                   Solve* solve) {
  for (PoseBlock& pose : poses) {
    auto it = counts.find(&pose);
    if (it != counts.end() && it->second < min_count) solve->HoldConstant(&pose);
  }
}

/// The per-frame data of one moving cluster while it is being adjusted.
struct ClusterState {
  ClusterMotion* motion;
  std::vector<int> frame_index;  // [frame - range.begin] → index in motion->frames, or -1
  std::vector<PoseBlock> cam_from_cluster;
  std::vector<PoseBlock> world_from_cluster;  // coupled modes only
};

class Adjuster {
 public:
  Adjuster(const TrackletTable& table, const StereoCamera& camera,
           const BundleAdjustmentOptions& options, MotionEstimate* estimate,
           const std::vector<bool>* held_out, const std::vector<bool>* fixed_cameras,
           bool clusters_only = false)
      : table_(table), camera_(camera), options_(options), est_(*estimate),
        clusters_only_(clusters_only) {
    if (held_out) held_out_ = *held_out;
    if (fixed_cameras) fixed_cameras_ = *fixed_cameras;
    fixed_cameras_.resize(est_.world_from_cam.size(), false);
    any_fixed_camera_ = std::find(fixed_cameras_.begin(), fixed_cameras_.end(), true) != fixed_cameras_.end();
    held_out_.resize(est_.landmark_in_cluster.size(), false);
    const FrameRange range = est_.range;
    for (const Pose& world_from_cam : est_.world_from_cam)
      cam_from_world_.push_back(PoseBlock::From(world_from_cam.inverse()));
    points_.resize(est_.landmark_in_cluster.size());
    for (size_t i = 0; i < points_.size(); ++i)
      for (int k = 0; k < 3; ++k) points_[i][k] = est_.landmark_in_cluster[i](k);
    for (ClusterMotion& motion : est_.clusters) {
      ClusterState cs{&motion, std::vector<int>(range.size(), -1), {}, {}};
      for (size_t k = 0; k < motion.frames.size(); ++k) {
        cs.frame_index[motion.frames[k] - range.begin] = static_cast<int>(k);
        cs.cam_from_cluster.push_back(PoseBlock::From(motion.cam_from_cluster[k]));
      }
      cluster_of_label_[motion.cluster] = static_cast<int>(clusters_.size());
      clusters_.push_back(std::move(cs));
    }
  }

  BundleAdjustmentSummary Run() {
    BundleAdjustmentSummary summary;
    if (clusters_only_ || options_.coupling == BaCoupling::kDecoupled) {
      // Step (1) and step (2) share no unknowns: every moving cluster's solve and the static
      // one may run side by side (options.runner). Each writes only its own poses and points
      // and its own summary, merged in a fixed order, so the result does not depend on the
      // runner. The static solve, the largest, is task 0 so that it starts first;
      // AdjustClusterMotions runs step (1) alone.
      const int n = static_cast<int>(clusters_.size());
      const int first_cluster_task = clusters_only_ ? 0 : 1;
      std::vector<BundleAdjustmentSummary> parts(n + 1);
      RunTasks(options_.runner.get(), n + first_cluster_task, [&](int task) {
        if (task < first_cluster_task)
          SolveStatic(&parts[n]);
        else
          SolveCluster(&clusters_[task - first_cluster_task], &parts[task - first_cluster_task]);
      });
      for (const BundleAdjustmentSummary& part : parts) {
        summary.iterations += part.iterations;
        summary.num_solves += part.num_solves;
        if (!part.usable && summary.usable) summary.why = part.why;
        summary.usable = summary.usable && part.usable;
      }
    } else {
      if (options_.coupling != BaCoupling::kFullyCoupled)
        for (ClusterState& cs : clusters_) SolveCluster(&cs, &summary);
      SolveCoupled(&summary);
    }
    WriteBack();
    return summary;
  }

 private:
  bool Usable(int landmark) const {
    return est_.landmark_cluster[landmark] >= 0 && est_.landmark_in_cluster[landmark].allFinite();
  }
  /// A landmark that enters the solves.
  bool Adjusted(int landmark) const { return Usable(landmark) && !held_out_[landmark]; }

  /// Step (1): one moving cluster's landmarks and per-frame T^{cq}_t.
  void SolveCluster(ClusterState* cs, BundleAdjustmentSummary* summary) {
    const int label = cs->motion->cluster;
    BundleAdjustmentOptions options = options_;
    if (options.moving_max_iterations >= 0) options.max_iterations = options.moving_max_iterations;
    Solve solve(camera_, options, "cluster " + std::to_string(label));
    ObservationCount counts;
    for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
      if (est_.landmark_cluster[i] != label || !Adjusted(i)) continue;
      for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
        const int k = cs->frame_index[obs.frame - est_.range.begin];
        if (k < 0) continue;
        if (solve.AddObservation(obs, &cs->cam_from_cluster[k], points_[i].data()))
          ++counts[&cs->cam_from_cluster[k]];
      }
    }
    HoldWeakPoses(cs->cam_from_cluster, counts, options_.min_observations_per_pose, &solve);
    if (options_.motion_prior_sigma_m > 0) AddMotionPriors(cs, label, counts, &solve);
    // Gauge: the cluster's frame is arbitrary up to SE(3); hold its first well-seen pose.
    for (PoseBlock& pose : cs->cam_from_cluster) {
      auto it = counts.find(&pose);
      if (it != counts.end() && it->second >= options_.min_observations_per_pose) {
        solve.HoldConstant(&pose);
        break;
      }
    }
    solve.Run(summary);
  }

  /// The constant-velocity prior (motion_prior_sigma_m) on every three consecutive frames
  /// whose poses the solve estimates (held weak poses would pull their neighbours towards
  /// their unrefined values). Camera poses are the solve's input: the static solve refines
  /// them at the same time, by centimetres against the prior's decimetres.
  void AddMotionPriors(ClusterState* cs, int label, const ObservationCount& counts, Solve* solve) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    int n = 0;
    for (int i = 0; i < static_cast<int>(points_.size()); ++i)
      if (est_.landmark_cluster[i] == label && Adjusted(i)) {
        centre += Eigen::Map<const Eigen::Vector3d>(points_[i].data());
        ++n;
      }
    if (n == 0) return;
    centre /= n;
    const auto well_seen = [&](int k) {
      const auto it = counts.find(&cs->cam_from_cluster[k]);
      return it != counts.end() && it->second >= options_.min_observations_per_pose;
    };
    const std::vector<int>& frames = cs->motion->frames;
    for (size_t k = 0; k + 2 < frames.size(); ++k) {
      if (frames[k + 1] != frames[k] + 1 || frames[k + 2] != frames[k] + 2) continue;
      if (!well_seen(k) || !well_seen(k + 1) || !well_seen(k + 2)) continue;
      MotionPriorTerm term;
      for (int i = 0; i < 3; ++i) term.world_from_cam[i] = est_.world_from_cam[frames[k + i] - est_.range.begin];
      term.centre = centre;
      term.sigma_m = options_.motion_prior_sigma_m;
      term.sigma_rad = options_.motion_prior_sigma_rad;
      solve->AddMotionPrior(&cs->cam_from_cluster[k], &cs->cam_from_cluster[k + 1],
                            &cs->cam_from_cluster[k + 2], term);
    }
  }

  /// Step (2) of the decoupled scheme: camera poses and static landmarks.
  void SolveStatic(BundleAdjustmentSummary* summary) {
    Solve solve(camera_, options_, "static");
    ObservationCount counts;
    AddStatic(&solve, &counts);
    HoldWeakPoses(cam_from_world_, counts, options_.min_observations_per_pose, &solve);
    HoldFixedCameras(&solve);
    if (!cam_from_world_.empty()) solve.HoldConstant(&cam_from_world_[0]);
    solve.Run(summary);
  }

  void HoldFixedCameras(Solve* solve) {
    for (size_t f = 0; f < cam_from_world_.size(); ++f)
      if (fixed_cameras_[f]) solve->HoldConstant(&cam_from_world_[f]);
  }

  /// A camera pose no solve moves: the gauge frame or a fixed one.
  bool HeldCamera(int frame) const { return frame == 0 || fixed_cameras_[frame]; }

  /// A static landmark that only held cameras observe is decoupled from every free unknown
  /// (its residuals involve no other parameter), so leaving it out changes no pose or other
  /// point; it keeps its position — in a warm window the map's, refined in the window where
  /// its frames were new. Most of a warm window's static landmarks are such (KITTI: ~2/3).
  bool OnlyHeldCamerasSee(int landmark) const {
    if (!any_fixed_camera_) return false;
    for (const StereoObservation& obs : table_.ObservationsOf(landmark, est_.range))
      if (!HeldCamera(obs.frame - est_.range.begin)) return false;
    return true;
  }

  /// Whether `point`, at its current estimate, is farther from the camera than
  /// far_depth_baselines (BundleAdjustmentOptions). The current depth, not the observation's
  /// own disparity, decides: choosing by the noisy measurement would keep exactly the
  /// observations whose noise enlarged the disparity, a bias towards near depths (measured: it
  /// shortened the generated outdoor sequences' scale;
  /// docs/experiments/2026-12-02-far-points-without-disparity.md).
  bool FarFrom(const PoseBlock& cam_from_world, const double* point) const {
    if (options_.far_depth_baselines <= 0) return false;
    const Eigen::Map<const Eigen::Quaterniond> q(cam_from_world.data());
    const double depth = (q * Eigen::Map<const Eigen::Vector3d>(point)).z() + cam_from_world.x[6];
    return depth > options_.far_depth_baselines * camera_.baseline;
  }

  void AddStatic(Solve* solve, ObservationCount* counts) {
    for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
      if (est_.landmark_cluster[i] != 0 || !Adjusted(i) || OnlyHeldCamerasSee(i)) continue;
      for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
        PoseBlock* pose = &cam_from_world_[obs.frame - est_.range.begin];
        const StereoObservation* use = &obs;
        StereoObservation far;
        if (FarFrom(*pose, points_[i].data())) {
          far = obs;
          far.cov(2, 2) += options_.far_disparity_sigma_px * options_.far_disparity_sigma_px;
          use = &far;
        }
        if (solve->AddObservation(*use, pose, points_[i].data())) ++(*counts)[pose];
      }
    }
  }

  /// The whole E: camera, static landmarks, and every moving cluster through P^q_t. A moving
  /// cluster's own SE(3) gauge is left to the Levenberg–Marquardt damping: holding one of its
  /// world poses would make that frame's observations pull on the camera pose.
  void SolveCoupled(BundleAdjustmentSummary* summary) {
    Solve solve(camera_, options_, "coupled");
    ObservationCount counts;
    AddStatic(&solve, &counts);
    for (ClusterState& cs : clusters_) {
      cs.world_from_cluster.clear();
      for (size_t k = 0; k < cs.motion->frames.size(); ++k) {
        const int f = cs.motion->frames[k] - est_.range.begin;
        cs.world_from_cluster.push_back(PoseBlock::From(cam_from_world_[f].ToPose().inverse() *
                                                        cs.cam_from_cluster[k].ToPose()));
      }
      const int label = cs.motion->cluster;
      for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
        if (est_.landmark_cluster[i] != label || !Adjusted(i)) continue;
        for (const StereoObservation& obs : table_.ObservationsOf(i, est_.range)) {
          const int f = obs.frame - est_.range.begin;
          const int k = cs.frame_index[f];
          if (k < 0) continue;
          if (solve.AddCoupledObservation(obs, &cam_from_world_[f], &cs.world_from_cluster[k],
                                          points_[i].data()))
            ++counts[&cs.world_from_cluster[k]];
        }
      }
      HoldWeakPoses(cs.world_from_cluster, counts, options_.min_observations_per_pose, &solve);
    }
    HoldWeakPoses(cam_from_world_, counts, options_.min_observations_per_pose, &solve);
    HoldFixedCameras(&solve);
    if (!cam_from_world_.empty()) solve.HoldConstant(&cam_from_world_[0]);
    solve.Run(summary);
    for (ClusterState& cs : clusters_)
      for (size_t k = 0; k < cs.motion->frames.size(); ++k) {
        const int f = cs.motion->frames[k] - est_.range.begin;
        cs.cam_from_cluster[k] =
            PoseBlock::From(cam_from_world_[f].ToPose() * cs.world_from_cluster[k].ToPose());
      }
  }

  /// Step (3): P^q_t = P^c_t T^{cq}_t, and the refined values back into the estimate.
  void WriteBack() {
    // Fixed poses are not written back: the quaternion round trip would perturb them in the
    // last bits, and the caller relies on them being exactly the map's.
    for (size_t f = 0; f < cam_from_world_.size() && !clusters_only_; ++f)
      if (!fixed_cameras_[f]) est_.world_from_cam[f] = cam_from_world_[f].ToPose().inverse();
    for (size_t i = 0; i < points_.size(); ++i)
      if (Usable(static_cast<int>(i)))
        est_.landmark_in_cluster[i] = Eigen::Vector3d(points_[i][0], points_[i][1], points_[i][2]);
    for (ClusterState& cs : clusters_) {
      ClusterMotion& m = *cs.motion;
      m.world_from_cluster.resize(m.frames.size());
      for (size_t k = 0; k < m.frames.size(); ++k) {
        m.cam_from_cluster[k] = cs.cam_from_cluster[k].ToPose();
        m.world_from_cluster[k] =
            est_.world_from_cam[m.frames[k] - est_.range.begin] * m.cam_from_cluster[k];
      }
    }
    for (size_t i = 0; i < points_.size(); ++i)
      if (held_out_[i] && Usable(static_cast<int>(i)) && !(clusters_only_ && est_.landmark_cluster[i] == 0))
        PlaceHeldOut(static_cast<int>(i));
  }

  /// Mean of the landmark's back-projections mapped into its cluster's frame by the refined
  /// poses; unchanged when none back-projects.
  void PlaceHeldOut(int landmark) {
    const int label = est_.landmark_cluster[landmark];
    const ClusterState* cs = nullptr;
    if (label > 0) {
      auto it = cluster_of_label_.find(label);
      if (it == cluster_of_label_.end()) return;
      cs = &clusters_[it->second];
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (const StereoObservation& obs : table_.ObservationsOf(landmark, est_.range)) {
      const int f = obs.frame - est_.range.begin;
      Pose cluster_from_cam;
      if (cs) {
        const int k = cs->frame_index[f];
        if (k < 0) continue;
        cluster_from_cam = cs->motion->cam_from_cluster[k].inverse();
      } else {
        cluster_from_cam = est_.world_from_cam[f];
      }
      Eigen::Vector3d p;
      if (!camera_.BackProject<double>(obs.x, &p)) continue;
      sum += cluster_from_cam * p;
      ++count;
    }
    if (count > 0) est_.landmark_in_cluster[landmark] = sum / count;
  }

  const TrackletTable& table_;
  const StereoCamera& camera_;
  const BundleAdjustmentOptions& options_;
  MotionEstimate& est_;
  const bool clusters_only_;  // AdjustClusterMotions: step (1) alone, the rest as given
  std::vector<PoseBlock> cam_from_world_;
  std::vector<std::array<double, 3>> points_;
  std::vector<ClusterState> clusters_;
  std::map<int, int> cluster_of_label_;
  std::vector<bool> held_out_;  // [landmark id]
  std::vector<bool> fixed_cameras_;  // [frame - range.begin]
  bool any_fixed_camera_ = false;
};

}  // namespace

namespace {

// A solve that failed or whose cost grew must not feed the next step: the estimate goes back
// to what was given, marked, and the log says so.
void FallBackWhenUnusable(const BundleAdjustmentSummary& summary, const MotionEstimate& given,
                          const char* what, MotionEstimate* estimate) {
  if (summary.usable) return;
  *estimate = given;
  estimate->adjustment_failed = true;
  GetLogger("backend")->warn("{} over frames {}..{} not usable ({}): the estimate it was given "
                             "is kept and marked", what, estimate->range.begin,
                             estimate->range.end - 1, summary.why);
}

}  // namespace

BundleAdjustmentSummary AdjustBundle(const TrackletTable& table, const StereoCamera& camera,
                                     const BundleAdjustmentOptions& options,
                                     MotionEstimate* estimate, const std::vector<bool>* held_out,
                                     const std::vector<bool>* fixed_cameras) {
  CSLAM_CHECK(static_cast<int>(estimate->world_from_cam.size()) == estimate->range.size(),
              "AdjustBundle: world_from_cam must have one pose per frame of the range");
  CSLAM_CHECK(estimate->landmark_cluster.size() == estimate->landmark_in_cluster.size(),
              "AdjustBundle: landmark_cluster and landmark_in_cluster must be parallel");
  const double initial = EvaluateChi2(table, camera, estimate);
  const MotionEstimate given = *estimate;
  BundleAdjustmentSummary summary =
      Adjuster(table, camera, options, estimate, held_out, fixed_cameras).Run();
  FallBackWhenUnusable(summary, given, "bundle adjustment", estimate);
  summary.initial_chi2 = initial;
  summary.final_chi2 = EvaluateChi2(table, camera, estimate);
  summary.num_residuals = estimate->num_residuals;
  return summary;
}

BundleAdjustmentSummary AdjustClusterMotions(const TrackletTable& table, const StereoCamera& camera,
                                             const BundleAdjustmentOptions& options,
                                             MotionEstimate* estimate) {
  CSLAM_CHECK(static_cast<int>(estimate->world_from_cam.size()) == estimate->range.size(),
              "AdjustClusterMotions: world_from_cam must have one pose per frame of the range");
  const double initial = EvaluateChi2(table, camera, estimate);
  const MotionEstimate given = *estimate;
  BundleAdjustmentSummary summary =
      Adjuster(table, camera, options, estimate, nullptr, nullptr, true).Run();
  FallBackWhenUnusable(summary, given, "cluster-motion adjustment", estimate);
  summary.initial_chi2 = initial;
  summary.final_chi2 = EvaluateChi2(table, camera, estimate);
  summary.num_residuals = estimate->num_residuals;
  return summary;
}

double EvaluateChi2(const TrackletTable& table, const StereoCamera& camera,
                    MotionEstimate* estimate, std::vector<double>* per_landmark_mean) {
  const FrameRange range = estimate->range;
  std::map<int, const ClusterMotion*> by_label;
  for (const ClusterMotion& m : estimate->clusters) by_label[m.cluster] = &m;
  const int n = static_cast<int>(estimate->landmark_cluster.size());
  if (per_landmark_mean) per_landmark_mean->assign(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<Pose> cam_from_world;
  for (const Pose& p : estimate->world_from_cam) cam_from_world.push_back(p.inverse());
  double chi2 = 0.0;
  int count = 0;
  for (int i = 0; i < n && i < table.num_landmarks(); ++i) {
    const int label = estimate->landmark_cluster[i];
    const Eigen::Vector3d& point = estimate->landmark_in_cluster[i];
    if (label < 0 || !point.allFinite()) continue;
    const ClusterMotion* motion = nullptr;
    if (label > 0) {
      auto it = by_label.find(label);
      if (it == by_label.end()) continue;
      motion = it->second;
    }
    double sum = 0.0;
    int num = 0;
    for (const StereoObservation& obs : table.ObservationsOf(i, range)) {
      Eigen::Vector3d p_in_cam;
      if (motion) {
        auto f = std::lower_bound(motion->frames.begin(), motion->frames.end(), obs.frame);
        if (f == motion->frames.end() || *f != obs.frame) continue;
        p_in_cam = motion->cam_from_cluster[f - motion->frames.begin()] * point;
      } else {
        p_in_cam = cam_from_world[obs.frame - range.begin] * point;
      }
      if (p_in_cam.z() == 0.0) continue;
      Eigen::Vector3d predicted;
      camera.Project(p_in_cam, &predicted);
      const Eigen::Vector3d e = obs.x - predicted;
      Eigen::Matrix3d info;
      double det;
      const double m2 = InvertSpd3(obs.cov, &info, &det) ? e.dot(info * e) : e.dot(obs.cov.ldlt().solve(e));
      sum += m2;
      ++num;
    }
    chi2 += sum;
    count += num;
    if (per_landmark_mean && num > 0) (*per_landmark_mean)[i] = sum / num;
  }
  estimate->chi2 = chi2;
  estimate->num_residuals = count;
  return chi2;
}

}  // namespace cslam
