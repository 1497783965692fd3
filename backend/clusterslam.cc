#include "backend/clusterslam.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "backend/bundle_adjustment.h"
#include "backend/covariance_floor.h"
#include "backend/labelling.h"
#include "backend/place_split.h"
#include "backend/point_tracks.h"
#include "core/errors.h"
#include "core/logging.h"
#include "core/timer.h"

namespace cslam {

void WindowPriorOptions::Check() const {
  CheckOption(max_iterations >= 1, "max_iterations", "must be >= 1",
              max_iterations);
  CheckOption(ba_iterations >= 1, "ba_iterations", "must be >= 1",
              ba_iterations);
  CheckOption(moving_ba_iterations >= 0, "moving_ba_iterations",
              "must be >= 0 (0: ba_iterations)", moving_ba_iterations);
  CheckOption(function_tolerance >= 0 && function_tolerance < 1,
              "function_tolerance", "must be in [0, 1)",
              function_tolerance);
  CheckOption(min_known_frames > 0 && min_known_frames <= 1,
              "min_known_frames", "must be in (0, 1]", min_known_frames);
  CheckOption(min_known_landmarks >= 0 && min_known_landmarks <= 1,
              "min_known_landmarks", "must be in [0, 1]",
              min_known_landmarks);
  CheckOption(free_known_frames >= 0, "free_known_frames",
              "must be >= 0", free_known_frames);
}

void WindowPriorOptions::Load(OptionsReader& reader) {
  reader.Read("enabled", &enabled);
  reader.Read("max_iterations", &max_iterations);
  reader.Read("ba_iterations", &ba_iterations);
  reader.Read("function_tolerance", &function_tolerance);
  reader.Read("moving_ba_iterations", &moving_ba_iterations);
  reader.Read("adjust_prior", &adjust_prior);
  reader.Read("keep_moving_labels", &keep_moving_labels);
  reader.Read("fix_known_poses", &fix_known_poses);
  reader.Read("free_known_frames", &free_known_frames);
  reader.Read("min_known_frames", &min_known_frames);
  reader.Read("min_known_landmarks", &min_known_landmarks);
}

ClusterSlamOptions ClusterSlamOptions::Indoor() {
  ClusterSlamOptions o;
  o.hac.epsilon = 60.0;
  o.consensus.chunk_length = 100;
  o.consensus.chunk_overlap = 25;
  return o;
}

ClusterSlamOptions ClusterSlamOptions::Outdoor() {
  ClusterSlamOptions o;
  o.hac.epsilon = 90.0;
  o.consensus.chunk_length = 200;
  o.consensus.chunk_overlap = 25;
  // [ours, measured] Road scenes keep a moving landmark in its cluster from window to window:
  // a warm window's first assignment has only the static model, and a car ahead moving along
  // the line of sight fits one static point about as well (docs/experiments/
  // 2026-12-07-far-cars-labelled-static-online.md). The pieces this leaves are joined at the
  // end of the run (map.track). Indoors, near boxes, it finds no more objects and places one
  // worse (docs/experiments/2026-12-07-sticky-labels-outdoors.md).
  o.assignment.favour_own_label = true;
  o.window_prior.keep_moving_labels = true;
  return o;
}

ClusterSlamOptions ClusterSlamOptions::Effective() const {
  ClusterSlamOptions o = *this;
  switch (ablation) {
    case ClusterSlamAblation::kNone: break;
    case ClusterSlamAblation::kNoUncertainty: o.distance.use_uncertainty = false; break;
    case ClusterSlamAblation::kNoImagePrior: o.distance.use_image_prior = false; break;
    case ClusterSlamAblation::kPointToPointIcp: o.motion.point_to_point_icp = true; break;
  }
  return o;
}

void ClusterSlamOptions::Check() const {
  CheckSection("distance", [&] { distance.Check(); });
  CheckSection("hac", [&] { hac.Check(); });
  CheckSection("consensus", [&] { consensus.Check(); });
  CheckSection("motion", [&] { motion.Check(); });
  CheckSection("assignment", [&] { assignment.Check(); });
  CheckSection("window_prior", [&] { window_prior.Check(); });
  CheckOption(max_iterations >= 1, "max_iterations", "must be >= 1", max_iterations);
  CheckOption(std::isfinite(convergence_vi) && convergence_vi >= 0, "convergence_vi",
              "must be >= 0 (nats)", convergence_vi);
  CheckOption(intermediate_ba_iterations >= 0, "intermediate_ba_iterations",
              "must be >= 0 (0 = shape initialisation only)", intermediate_ba_iterations);
  CheckOption(std::isfinite(min_pixel_sigma) && min_pixel_sigma >= 0, "min_pixel_sigma",
              "must be >= 0 px", min_pixel_sigma);
  CheckOption(refine_half_window >= 0, "refine_half_window", "must be >= 0 frames",
              refine_half_window);
}

void ClusterSlamOptions::Load(OptionsReader& reader) {
  reader.ReadSection("distance", &distance);
  reader.ReadSection("hac", &hac);
  reader.ReadSection("consensus", &consensus);
  reader.ReadSection("motion", &motion);
  reader.ReadSection("assignment", &assignment);
  reader.ReadSection("window_prior", &window_prior);
  reader.Read("ablation", kAblationNames, &ablation);
  reader.Read("max_iterations", &max_iterations);
  reader.Read("refine_half_window", &refine_half_window);
  reader.Read("min_pixel_sigma", &min_pixel_sigma);
  reader.Read("convergence_vi", &convergence_vi);
  reader.Read("intermediate_ba_iterations", &intermediate_ba_iterations);
  reader.Read("warm_start", &warm_start);
  reader.Read("reuse_unchanged_clusters", &reuse_unchanged_clusters);
}

namespace {
std::vector<int> ObservationCounts(const TrackletTable& table, FrameRange range) {
  std::vector<int> observations(table.num_landmarks(), 0);
  for (int l : table.LandmarksIn(range))
    observations[l] = static_cast<int>(table.ObservationsOf(l, range).size());
  return observations;
}

}  // namespace

std::vector<int> ClusterLandmarks(const TrackletTable& table, const PointTracks& tracks,
                                  FrameRange range, const ClusterSlamOptions& options,
                                  const std::vector<int>* previous, ConsensusSummary* summary) {
  std::vector<ChunkLabels> chunk_labels;
  for (const FrameRange& chunk : ChunksOf(range, options.consensus)) {
    SparseDistances d = ComputeMotionDistances(table, tracks, chunk, options.distance);
    ChunkLabels cl;
    cl.landmarks = d.landmarks;
    cl.labels = CompleteLinkageHac(std::move(d), options.hac);
    chunk_labels.push_back(std::move(cl));
  }
  const std::vector<int> consensus =
      ConsensusLabels(chunk_labels, table.num_landmarks(), options.consensus, summary);
  return StaticFirstLabels(consensus, ObservationCounts(table, range), previous);
}

namespace {

// Iterations >= 2 with the model assignment: reassign, merge, and re-cluster the outliers
// among themselves with Eq. 1 + HAC (a strong image prior: what is left is moving objects,
// told apart by where they are in the image).
std::vector<int> AssignAndRecluster(const TrackletTable& table, const PointTracks& raw,
                                    FrameRange range, const std::vector<int>& labels,
                                    const MotionEstimate& estimate,
                                    const ClusterSlamOptions& options,
                                    IterationDiagnostics* diag, std::vector<int>* reclusterings) {
  const ModelAssignment a =
      AssignToMotionModels(raw, labels, estimate, options.assignment, reclusterings);
  std::vector<int> next = a.labels;
  diag->reassigned = a.reassigned;
  diag->outliers = static_cast<int>(a.outliers.size());
  diag->merges = a.merges;
  if (static_cast<int>(a.outliers.size()) >= options.assignment.min_outlier_cluster) {
    PointTracks outliers(raw.size());
    for (int l : a.outliers) outliers[l] = raw[l];
    ClusterSlamOptions o = options;
    o.distance.alpha = options.assignment.outlier_alpha;
    o.distance.max_extent_m = options.assignment.outlier_max_extent_m;
    o.consensus.min_cluster_size = options.assignment.min_outlier_cluster;
    const std::vector<int> groups = ClusterLandmarks(table, outliers, range, o, nullptr);
    const int base = next.empty() ? 0 : *std::max_element(next.begin(), next.end()) + 1;
    for (int l : a.outliers)
      if (groups[l] >= 0) next[l] = base + groups[l];
  }
  return StaticFirstLabels(next, ObservationCounts(table, range), &labels);
}

// The motion prior (BundleAdjustmentOptions::motion_prior_sigma_m) is the last step, once the
// labels are settled. Inside the loop it steers the model assignment, and in batch mode that
// cost objects found (docs/experiments/2026-12-03-object-pose-noise-and-motion-prior.md), so
// the loop runs without it.
void DropMotionPrior(BundleAdjustmentOptions* ba) {
  ba->motion_prior_sigma_m = 0.0;
  ba->motion_prior_sigma_rad = 0.0;
}

void ApplyMotionPrior(const TrackletTable& table, const StereoCamera& camera,
                      const BundleAdjustmentOptions& ba, MotionEstimate* estimate) {
  if (ba.motion_prior_sigma_m <= 0 || estimate->clusters.empty()) return;
  const Timer timer;
  const BundleAdjustmentSummary s = AdjustClusterMotions(table, camera, ba, estimate);
  GetLogger("backend")->debug("clusterslam: motion prior on {} moving clusters, chi2 {:.1f} -> "
                              "{:.1f}, {:.1f} ms",
                              estimate->clusters.size(), s.initial_chi2, s.final_chi2,
                              timer.ElapsedMs());
}

}  // namespace

BackendResult RunClusterSlam(const TrackletTable& table, const StereoCamera& camera,
                             FrameRange range, const ClusterSlamOptions& options) {
  MovingClusterCache cache;
  const bool reuse = options.reuse_unchanged_clusters;
  return RunClusterSlam(
      table, camera, range, options,
      [&cache, reuse](const TrackletTable& t, const StereoCamera& c, FrameRange r,
                      const std::vector<int>& l, const MotionEstimationOptions& o,
                      const MotionEstimate* w) {
        MotionEstimate e = EstimateMotions(t, c, r, l, o, w, reuse ? &cache : nullptr);
        if (reuse && cache.reused > 0)
          GetLogger("backend")->debug("clusterslam: {} moving clusters unchanged, not re-estimated",
                                      cache.reused);
        return e;
      });
}

namespace {

// The loop's last labelling still holds the clusters its last re-clustering made.
void JudgeFinalClusters(const PointTracks& raw, const ModelAssignmentOptions& options,
                        MotionEstimate* estimate) {
  if (const int removed = DissolveUnsupportedClusters(raw, options, estimate))
    GetLogger("backend")->info("clusterslam: {} moving cluster(s) dissolved by the final check "
                               "(the static world explains them, or too few of their landmarks "
                               "fit their motion)", removed);
  if (const int added = SplitClustersByPlace(options.split_gap_m, options.min_outlier_cluster, estimate))
    GetLogger("backend")->info("clusterslam: {} moving cluster(s) split off by place (groups of "
                               "landmarks over {:.1f} m apart)", added, options.split_gap_m);
}

}  // namespace

BackendResult RunClusterSlam(const TrackletTable& input_table, const StereoCamera& camera,
                             FrameRange range, const ClusterSlamOptions& options,
                             const MotionEstimator& estimator) {
  const Timer total;
  ClusterSlamOptions opts = options.Effective();
  opts.Check();
  // The favour keeps the labels the map gave a warm window; here every label is the loop's
  // own guess (a batch run's whole-sequence solve: outdoor seeds 1-4 ME_r max 0.96 -> 3.2 deg
  // with it on, docs/experiments/2026-12-07-sticky-labels-outdoors.md).
  opts.assignment.favour_own_label = false;
  const BundleAdjustmentOptions final_ba = opts.motion.bundle_adjustment;
  DropMotionPrior(&opts.motion.bundle_adjustment);
  const std::optional<TrackletTable> floored =
      FloorPixelCovariances(input_table, range, opts.min_pixel_sigma);
  const TrackletTable& table = floored ? *floored : input_table;
  auto log = GetLogger("backend");
  BackendResult result;
  result.method = "clusterslam";

  const PointTracks raw = BackProjectTracks(table, camera, range);
  PointTracks tracks = raw;
  std::vector<int> labels;
  std::vector<int> reclusterings(raw.size(), 0);  // per landmark, over the loop
  bool adjusted = false;  // does result.estimate include the bundle adjustment?
  for (int k = 1; k <= opts.max_iterations; ++k) {
    IterationDiagnostics diag;
    diag.iteration = k;
    Timer timer;
    ConsensusSummary consensus;
    const bool assign = opts.assignment.enabled && !labels.empty();
    std::vector<int> next =
        assign ? AssignAndRecluster(table, raw, range, labels, result.estimate, opts, &diag,
                                    &reclusterings)
               : ClusterLandmarks(table, tracks, range, opts, labels.empty() ? nullptr : &labels,
                                  &consensus);
    diag.clustering_ms = timer.ElapsedMs();
    diag.num_clusters = next.empty() ? 0 : *std::max_element(next.begin(), next.end()) + 1;
    diag.vi_to_previous = labels.empty() ? 0.0 : LabellingVariation(labels, next);
    // A labelling with fewer clusters is a structural change however few landmarks it moves
    // (a small cluster dissolved or merged): estimate it.
    const int previous_clusters =
        labels.empty() ? 0 : *std::max_element(labels.begin(), labels.end()) + 1;
    const bool stable = !labels.empty() && diag.vi_to_previous <= opts.convergence_vi &&
                        diag.num_clusters >= previous_clusters;
    if (stable) {
      // (Nearly) the partition we already have an estimate for: keep it.
      diag.chi2 = result.estimate.chi2;
      result.iterations.push_back(diag);
      log->info("clusterslam iteration {}: {} clusters, labelling stable", k, diag.num_clusters);
      break;
    }
    labels = std::move(next);
    timer.Reset();
    MotionEstimationOptions motion = opts.motion;
    int& ba_iterations = motion.bundle_adjustment.max_iterations;
    if (k < opts.max_iterations && opts.intermediate_ba_iterations < ba_iterations) {
      ba_iterations = opts.intermediate_ba_iterations;
      if (ba_iterations == 0) motion.run_bundle_adjustment = false;
    }
    result.estimate = estimator(table, camera, range, labels, motion,
                                opts.warm_start && k > 1 ? &result.estimate : nullptr);
    adjusted = motion.run_bundle_adjustment &&
               ba_iterations == opts.motion.bundle_adjustment.max_iterations;
    diag.estimation_ms = timer.ElapsedMs();
    diag.chi2 = result.estimate.chi2;
    result.iterations.push_back(diag);
    if (assign)
      log->info("clusterslam iteration {}: {} clusters ({} reassigned, {} outliers re-clustered, "
                "{} merges), VI {:.4f}, chi2 {:.1f}, assignment {:.1f} ms, estimation {:.1f} ms",
                k, diag.num_clusters, diag.reassigned, diag.outliers, diag.merges,
                diag.vi_to_previous, diag.chi2, diag.clustering_ms, diag.estimation_ms);
    else
      log->info("clusterslam iteration {}: {} clusters (IVC {} sweeps{}), VI {:.4f}, chi2 {:.1f}, "
                "clustering {:.1f} ms, estimation {:.1f} ms",
                k, diag.num_clusters, consensus.iterations,
                consensus.converged ? "" : ", not stable", diag.vi_to_previous, diag.chi2,
                diag.clustering_ms, diag.estimation_ms);
    if (k < opts.max_iterations && !opts.assignment.enabled)
      tracks = RefineTracks(table, camera, range, result.estimate, opts.refine_half_window);
  }
  if (!adjusted && opts.motion.run_bundle_adjustment) {
    const Timer timer;
    result.estimate = estimator(table, camera, range, labels, opts.motion,
                                opts.warm_start ? &result.estimate : nullptr);
    result.iterations.back().estimation_ms += timer.ElapsedMs();
    result.iterations.back().chi2 = result.estimate.chi2;
    log->info("clusterslam: bundle adjustment of the final labelling, chi2 {:.1f}, {:.1f} ms",
              result.estimate.chi2, timer.ElapsedMs());
  }
  // The estimator owns landmark_cluster, but the loop's labelling is the reference.
  if (result.estimate.landmark_cluster.empty()) result.estimate.landmark_cluster = labels;
  if (opts.assignment.enabled) JudgeFinalClusters(raw, opts.assignment, &result.estimate);
  if (opts.motion.run_bundle_adjustment) ApplyMotionPrior(table, camera, final_ba, &result.estimate);
  result.time_s = total.ElapsedS();
  return result;
}

bool PriorIsUsable(const WindowPrior& prior, const TrackletTable& table, FrameRange range,
                   const WindowPriorOptions& options, std::string* why) {
  auto refuse = [why](std::string reason) {
    if (why) *why = std::move(reason);
    return false;
  };
  if (!(prior.range == range)) return refuse("the prior is for another range");
  if (static_cast<int>(prior.world_from_cam.size()) != range.size())
    return refuse("the prior needs one entry per frame");
  if (!prior.world_from_cam.empty() && !prior.world_from_cam.front())
    return refuse("no camera pose at the window's first frame");
  const int known_frames = prior.KnownFrames();
  if (known_frames < options.min_known_frames * range.size())
    return refuse(fmt::format("{} of {} frames have a camera pose", known_frames, range.size()));
  if (prior.static_point.size() != prior.landmark_cluster.size())
    return refuse("static_point and landmark_cluster differ in size");
  int tracked = 0, labelled = 0, positioned_static = 0;
  for (int l : table.LandmarksIn(range, 4)) {
    ++tracked;
    const int c = prior.ClusterOf(l);
    if (c >= 0) ++labelled;
    if (c == 0 && prior.static_point[l].allFinite()) ++positioned_static;
  }
  if (labelled < options.min_known_landmarks * tracked)
    return refuse(fmt::format("{} of {} landmarks have a cluster", labelled, tracked));
  if (positioned_static == 0) return refuse("no static landmark has a position");
  return true;
}

BackendResult RunClusterSlamWindow(const TrackletTable& input_table, const StereoCamera& camera,
                                   FrameRange range, const ClusterSlamOptions& options,
                                   const WindowPrior* prior) {
  ClusterSlamOptions opts = options.Effective();
  opts.Check();
  const BundleAdjustmentOptions prior_ba = opts.motion.bundle_adjustment;
  DropMotionPrior(&opts.motion.bundle_adjustment);
  auto log = GetLogger("backend");
  std::string why = "no prior";
  if (!opts.window_prior.enabled) why = "warm start disabled";
  if (!opts.window_prior.enabled || !prior ||
      !PriorIsUsable(*prior, input_table, range, opts.window_prior, &why)) {
    log->info("window {}..{}: cold start ({})", range.begin, range.end - 1, why);
    return RunClusterSlam(input_table, camera, range, options);
  }
  const Timer total;
  const std::optional<TrackletTable> floored =
      FloorPixelCovariances(input_table, range, opts.min_pixel_sigma);
  const TrackletTable& table = floored ? *floored : input_table;
  BackendResult result;
  result.method = "clusterslam";
  result.warm_started = true;
  const int n = table.num_landmarks();
  const PointTracks raw = BackProjectTracks(table, camera, range);
  const std::vector<int> counts = ObservationCounts(table, range);

  // Iteration 1: the prior itself, as an estimate without adjustment. Its labels are the
  // map's (relabelled static-first); landmarks new to the map stay unlabelled until the
  // model assignment below places them.
  Timer timer;
  std::vector<int> map_labels(n, -1);
  for (int l : table.LandmarksIn(range)) {
    const int c = prior->ClusterOf(l);
    map_labels[l] = c > 0 && !opts.window_prior.keep_moving_labels ? -1 : c;
  }
  std::vector<int> labels = StaticFirstLabels(map_labels, counts, &map_labels);
  MotionEstimate start;
  start.range = range;
  start.world_from_cam = CompleteCameraPoses(*prior, table, camera, opts.motion.shape_init);
  start.landmark_cluster.assign(n, -1);
  start.landmark_in_cluster.assign(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (int l = 0; l < n; ++l)
    if (labels[l] == 0 && prior->static_point[l].allFinite()) {
      start.landmark_cluster[l] = 0;
      start.landmark_in_cluster[l] = prior->static_point[l];
    }
  MotionEstimationOptions first = opts.motion;
  first.run_bundle_adjustment = opts.window_prior.adjust_prior;
  first.bundle_adjustment.max_iterations = opts.window_prior.ba_iterations;
  if (opts.window_prior.function_tolerance > 0)
    first.bundle_adjustment.function_tolerance = opts.window_prior.function_tolerance;
  if (opts.window_prior.moving_ba_iterations > 0)
    first.bundle_adjustment.moving_max_iterations = opts.window_prior.moving_ba_iterations;
  std::vector<bool> fixed_cameras(range.size(), false);
  if (opts.window_prior.fix_known_poses) {
    // The newest `free_known_frames` known poses stay free: the map has each frame's pose from
    // the window where it was newest, least constrained; letting the last ones move keeps the
    // new frames from being chained to them rigidly (all held: outdoor seed 1 drifts 3.5×).
    int free_left = opts.window_prior.free_known_frames;
    for (int k = range.size() - 1; k >= 0; --k) {
      if (!prior->world_from_cam[k]) continue;
      if (free_left > 0) {
        --free_left;
        continue;
      }
      fixed_cameras[k] = true;
    }
  }
  result.estimate =
      EstimateMotions(table, camera, range, labels, first, &start, nullptr, &fixed_cameras);
  {
    IterationDiagnostics diag;
    diag.iteration = 1;
    diag.num_clusters = *std::max_element(labels.begin(), labels.end()) + 1;
    diag.estimation_ms = timer.ElapsedMs();
    diag.chi2 = result.estimate.chi2;
    result.iterations.push_back(diag);
    log->info("clusterslam window {}..{} warm start: {} clusters from the map, {} of {} frames "
              "posed, chi2 {:.1f}, {:.1f} ms",
              range.begin, range.end - 1, diag.num_clusters, prior->KnownFrames(), range.size(),
              diag.chi2, diag.estimation_ms);
  }

  MotionEstimationOptions motion = opts.motion;
  motion.bundle_adjustment.max_iterations = opts.window_prior.ba_iterations;
  if (opts.window_prior.function_tolerance > 0)
    motion.bundle_adjustment.function_tolerance = opts.window_prior.function_tolerance;
  if (opts.window_prior.moving_ba_iterations > 0)
    motion.bundle_adjustment.moving_max_iterations = opts.window_prior.moving_ba_iterations;
  MovingClusterCache cache;
  std::vector<int> reclusterings(raw.size(), 0);  // per landmark, over this window's rounds
  bool adjusted = false;
  for (int round = 1; round <= opts.window_prior.max_iterations; ++round) {
    IterationDiagnostics diag;
    diag.iteration = round + 1;
    timer.Reset();
    std::vector<int> next =
        AssignAndRecluster(table, raw, range, labels, result.estimate, opts, &diag,
                           &reclusterings);
    diag.clustering_ms = timer.ElapsedMs();
    diag.num_clusters = next.empty() ? 0 : *std::max_element(next.begin(), next.end()) + 1;
    diag.vi_to_previous = LabellingVariation(labels, next);
    if (adjusted && diag.vi_to_previous <= opts.convergence_vi) {
      diag.chi2 = result.estimate.chi2;
      result.iterations.push_back(diag);
      log->info("clusterslam iteration {}: {} clusters, labelling stable", diag.iteration,
                diag.num_clusters);
      break;
    }
    labels = std::move(next);
    timer.Reset();
    result.estimate = EstimateMotions(table, camera, range, labels, motion, &result.estimate,
                                      opts.reuse_unchanged_clusters ? &cache : nullptr,
                                      &fixed_cameras);
    adjusted = true;
    diag.estimation_ms = timer.ElapsedMs();
    diag.chi2 = result.estimate.chi2;
    result.iterations.push_back(diag);
    log->info("clusterslam iteration {}: {} clusters ({} reassigned, {} outliers re-clustered, "
              "{} merges), VI {:.4f}, chi2 {:.1f}, assignment {:.1f} ms, estimation {:.1f} ms",
              diag.iteration, diag.num_clusters, diag.reassigned, diag.outliers, diag.merges,
              diag.vi_to_previous, diag.chi2, diag.clustering_ms, diag.estimation_ms);
  }
  if (result.estimate.landmark_cluster.empty()) result.estimate.landmark_cluster = labels;
  JudgeFinalClusters(raw, opts.assignment, &result.estimate);
  if (adjusted) {
    // With the window rounds' own iteration limits (window_prior.ba_iterations).
    BundleAdjustmentOptions final_ba = motion.bundle_adjustment;
    final_ba.motion_prior_sigma_m = prior_ba.motion_prior_sigma_m;
    final_ba.motion_prior_sigma_rad = prior_ba.motion_prior_sigma_rad;
    ApplyMotionPrior(table, camera, final_ba, &result.estimate);
  }
  result.time_s = total.ElapsedS();
  return result;
}

}  // namespace cslam
