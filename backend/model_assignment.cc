#include "backend/model_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "backend/place_split.h"
#include "core/logging.h"

namespace cslam {

void ModelAssignmentOptions::Check() const {
  CheckOption(std::isfinite(fit_threshold) && fit_threshold > 0, "fit_threshold",
              "must be a reduced chi-square > 0", fit_threshold);
  CheckOption(std::isfinite(split_gap_m) && split_gap_m >= 0, "split_gap_m",
              "must be >= 0 m (0 = off)", split_gap_m);
  CheckOption(std::isfinite(static_margin) && static_margin >= 0, "static_margin",
              "must be >= 0", static_margin);
  CheckOption(min_coverage > 0 && min_coverage <= 1, "min_coverage",
              "must be in (0, 1]", min_coverage);
  CheckOption(merge_fraction > 0 && merge_fraction <= 1, "merge_fraction",
              "must be in (0, 1]", merge_fraction);
  CheckOption(std::isfinite(merge_ratio) && merge_ratio >= 1, "merge_ratio",
              "must be >= 1", merge_ratio);
  CheckOption(std::isfinite(merge_slack) && merge_slack >= 0, "merge_slack",
              "must be >= 0", merge_slack);
  CheckOption(std::isfinite(outlier_alpha) && outlier_alpha >= 0, "outlier_alpha",
              "must be >= 0", outlier_alpha);
  CheckOption(std::isfinite(outlier_max_extent_m) && outlier_max_extent_m >= 0,
              "outlier_max_extent_m", "must be >= 0 m (0 = off)",
              outlier_max_extent_m);
  CheckOption(min_outlier_cluster >= 1, "min_outlier_cluster", "must be >= 1",
              min_outlier_cluster);
  CheckOption(max_dropped_samples >= 0, "max_dropped_samples", "must be >= 0",
              max_dropped_samples);
  CheckOption(std::isfinite(sample_gate_chi2) && sample_gate_chi2 > 0,
              "sample_gate_chi2", "must be a chi-square > 0", sample_gate_chi2);
  CheckOption(min_own_fit_fraction >= 0 && min_own_fit_fraction <= 1,
              "min_own_fit_fraction", "must be in [0, 1]", min_own_fit_fraction);
  CheckOption(core_cluster_landmarks >= 0, "core_cluster_landmarks",
              "must be >= 0", core_cluster_landmarks);
  CheckOption(min_cluster_landmarks >= 0, "min_cluster_landmarks", "must be >= 0",
              min_cluster_landmarks);
  CheckOption(max_reclusterings >= 1, "max_reclusterings", "must be >= 1",
              max_reclusterings);
  CheckSection("moving_test", [&] { moving_test.Check(); });
  CheckOption(std::isfinite(min_relative_motion) && min_relative_motion >= 0,
              "min_relative_motion", "must be >= 0 (RMS / mean range)",
              min_relative_motion);
}

void ModelAssignmentOptions::Load(OptionsReader& reader) {
  reader.Read("enabled", &enabled);
  reader.Read("fit_threshold", &fit_threshold);
  reader.Read("static_margin", &static_margin);
  reader.Read("favour_own_label", &favour_own_label);
  reader.Read("split_gap_m", &split_gap_m);
  reader.Read("min_coverage", &min_coverage);
  reader.Read("merge_fraction", &merge_fraction);
  reader.Read("merge_ratio", &merge_ratio);
  reader.Read("merge_slack", &merge_slack);
  reader.Read("outlier_alpha", &outlier_alpha);
  reader.Read("min_outlier_cluster", &min_outlier_cluster);
  reader.Read("outlier_max_extent_m", &outlier_max_extent_m);
  reader.Read("max_dropped_samples", &max_dropped_samples);
  reader.Read("sample_gate_chi2", &sample_gate_chi2);
  reader.Read("min_cluster_landmarks", &min_cluster_landmarks);
  reader.Read("min_own_fit_fraction", &min_own_fit_fraction);
  reader.Read("core_cluster_landmarks", &core_cluster_landmarks);
  reader.Read("test_moving", &test_moving);
  reader.Read("min_relative_motion", &min_relative_motion);
  reader.ReadSection("moving_test", &moving_test);
  reader.Read("max_reclusterings", &max_reclusterings);
}

namespace {

constexpr int kMinSamples = 4;

// One cluster's motion as cluster-from-camera poses indexed by frame − first.
struct Model {
  int label = -1;
  int first = 0;
  std::vector<Pose> cluster_from_cam;
  std::vector<char> has;

  const Pose* At(int frame) const {
    const int k = frame - first;
    return k >= 0 && k < static_cast<int>(has.size()) && has[k] ? &cluster_from_cam[k] : nullptr;
  }
};

bool Finite(const Pose& p) { return p.matrix().allFinite(); }

std::vector<Model> ModelsOf(const MotionEstimate& estimate) {
  std::vector<Model> models;
  if (!estimate.world_from_cam.empty()) {
    Model s;
    s.label = 0;
    s.first = estimate.range.begin;
    s.cluster_from_cam = estimate.world_from_cam;
    s.has.assign(s.cluster_from_cam.size(), 0);
    for (size_t k = 0; k < s.has.size(); ++k) s.has[k] = Finite(s.cluster_from_cam[k]);
    models.push_back(std::move(s));
  }
  for (const ClusterMotion& c : estimate.clusters) {
    if (c.frames.empty()) continue;
    Model m;
    m.label = c.cluster;
    m.first = c.frames.front();
    const int span = c.frames.back() - m.first + 1;
    m.cluster_from_cam.assign(span, Pose::Identity());
    m.has.assign(span, 0);
    for (size_t k = 0; k < c.frames.size(); ++k) {
      const Pose p = c.cam_from_cluster[k].inverse();
      if (!Finite(p)) continue;
      m.cluster_from_cam[c.frames[k] - m.first] = p;
      m.has[c.frames[k] - m.first] = 1;
    }
    models.push_back(std::move(m));
  }
  return models;
}

// `info` = the samples' camera-frame information matrices Σ⁻¹ (precomputed per landmark).
// Up to `max_dropped` samples whose χ² against the mean exceeds `gate` are left out, worst
// first, the mean re-estimated each time: a track is judged on what most of it says.
// `mean` (may be null) receives the kept samples' mean in the model's frame.
double CostUnder(const PointTrack& track, const std::vector<Eigen::Matrix3d>& info,
                 const Model& model, double min_coverage, int max_dropped, double gate,
                 Eigen::Vector3d* mean_out = nullptr) {
  const auto& samples = track.samples;
  thread_local std::vector<Eigen::Vector3d> y;
  thread_local std::vector<Eigen::Matrix3d> w;
  thread_local std::vector<char> kept;
  y.clear();
  w.clear();
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < samples.size(); ++k) {
    const Pose* p = model.At(samples[k].frame);
    if (!p) continue;
    const Eigen::Matrix3d r = p->linear();
    y.push_back(*p * samples[k].point);
    w.push_back(r * info[k] * r.transpose());
    a += w.back();
    b += w.back() * y.back();
  }
  const int n = static_cast<int>(y.size());
  if (n < kMinSamples || n < min_coverage * static_cast<double>(samples.size())) return -1.0;
  kept.assign(n, 1);
  int used = n;
  Eigen::Vector3d mean = a.ldlt().solve(b);
  double chi2 = 0.0;
  for (int dropped = 0;; ++dropped) {
    chi2 = 0.0;
    int worst = -1;
    double worst_chi2 = gate;
    for (int k = 0; k < n; ++k) {
      if (!kept[k]) continue;
      const double c = (y[k] - mean).dot(w[k] * (y[k] - mean));
      chi2 += c;
      if (c > worst_chi2) worst_chi2 = c, worst = k;
    }
    if (worst < 0 || dropped >= max_dropped || used <= kMinSamples) break;
    kept[worst] = 0;
    --used;
    a -= w[worst];
    b -= w[worst] * y[worst];
    mean = a.ldlt().solve(b);
  }
  const double cost = chi2 / (3.0 * used - 3.0);
  if (mean_out) *mean_out = mean;
  return std::isfinite(cost) ? cost : -1.0;
}

std::vector<Eigen::Matrix3d> Informations(const PointTrack& track) {
  std::vector<Eigen::Matrix3d> info;
  info.reserve(track.samples.size());
  for (const PointSample& s : track.samples) info.push_back(s.cov.inverse());
  return info;
}

// Whether moving clusters p and q of `estimate` lie more than gap_m apart at the first frame
// both have a pose at (their landmarks mapped into the world there); false without one.
bool ApartInTheWorld(const MotionEstimate& estimate, int p, int q, double gap_m) {
  const ClusterMotion* a = estimate.FindCluster(p);
  const ClusterMotion* b = estimate.FindCluster(q);
  if (!a || !b) return false;
  for (size_t i = 0, j = 0; i < a->frames.size() && j < b->frames.size();) {
    if (a->frames[i] < b->frames[j]) { ++i; continue; }
    if (b->frames[j] < a->frames[i]) { ++j; continue; }
    std::vector<Eigen::Vector3d> pa, pb;
    const size_t n = std::min(estimate.landmark_cluster.size(), estimate.landmark_in_cluster.size());
    for (size_t l = 0; l < n; ++l) {
      if (!estimate.landmark_in_cluster[l].allFinite()) continue;
      if (estimate.landmark_cluster[l] == p) pa.push_back(a->world_from_cluster[i] * estimate.landmark_in_cluster[l]);
      if (estimate.landmark_cluster[l] == q) pb.push_back(b->world_from_cluster[j] * estimate.landmark_in_cluster[l]);
    }
    return !pa.empty() && !pb.empty() && SeparatedByGap(pa, pb, gap_m);
  }
  return false;
}

}  // namespace

double ModelCost(const PointTrack& track, const MotionEstimate& estimate, int label,
                 double min_coverage, int max_dropped, double gate_chi2) {
  for (const Model& m : ModelsOf(estimate))
    if (m.label == label)
      return CostUnder(track, Informations(track), m, min_coverage, max_dropped, gate_chi2);
  return -1.0;
}

double RelativeMotion(const MotionEstimate& estimate, const std::vector<int>& labels, int label) {
  const ClusterMotion* motion = estimate.FindCluster(label);
  if (!motion || motion->frames.empty()) return -1.0;
  double squared = 0.0, range = 0.0;
  long long samples = 0;
  const size_t n = std::min(labels.size(), estimate.landmark_in_cluster.size());
  for (size_t l = 0; l < n; ++l) {
    if (labels[l] != label || !estimate.landmark_in_cluster[l].allFinite()) continue;
    const Eigen::Vector3d& x = estimate.landmark_in_cluster[l];
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Pose& p : motion->world_from_cluster) mean += p * x;
    mean /= static_cast<double>(motion->frames.size());
    for (size_t k = 0; k < motion->frames.size(); ++k) {
      squared += (motion->world_from_cluster[k] * x - mean).squaredNorm();
      range += (motion->cam_from_cluster[k] * x).norm();
      ++samples;
    }
  }
  if (samples == 0 || !(range > 0)) return -1.0;
  const double rel = std::sqrt(squared / samples) / (range / samples);
  return std::isfinite(rel) ? rel : -1.0;
}

namespace {

MovingTestResult TestModel(const PointTracks& tracks, const std::vector<int>& labels,
                           const Model& world, const Model& own,
                           const MovingTestOptions& options) {
  std::vector<const PointTrack*> members;
  const size_t n = std::min(labels.size(), tracks.size());
  for (size_t l = 0; l < n; ++l)
    if (labels[l] == own.label) members.push_back(&tracks[l]);
  return TestMoving(members, [&world](int f) { return world.At(f); },
                    [&own](int f) { return own.At(f); }, options);
}

// Whether moving cluster `own` has earned its existence (see the header), given how many of
// its landmarks its motion covers and how many of those fit it; logged under `stage`.
bool ShouldDissolve(const char* stage, int fits, int covered, const PointTracks& tracks,
                    const std::vector<int>& labels, const MotionEstimate& estimate,
                    const Model* world, const Model& own, const ModelAssignmentOptions& options) {
  // A big core of fitting landmarks stands on its own (the rest of the cluster is another
  // body's and is re-clustered); a small cluster must also be consistent.
  bool dissolve = fits < options.min_cluster_landmarks ||
                  (fits < options.core_cluster_landmarks &&
                   fits < options.min_own_fit_fraction * static_cast<double>(covered));
  double rel = -1.0;
  if (!dissolve && options.min_relative_motion > 0) {
    rel = RelativeMotion(estimate, labels, own.label);
    dissolve = rel >= 0 && rel < options.min_relative_motion;
  }
  MovingTestResult test;
  if (!dissolve && options.test_moving) {
    if (world) test = TestModel(tracks, labels, *world, own, options.moving_test);
    dissolve = !test.moving;  // no static world: nothing shows it moves
  }
  GetLogger("backend")->debug(
      "{}: cluster {} {} ({} of {} landmarks fit its motion, relative motion {:.4f}; moving "
      "test: chi2 static {:.1f} own {:.1f}, difference {:.1f} against {:.1f} for {} dof, {} "
      "landmarks in {} frames, disparity offsets {:.2f} / {:.2f} px)",
      stage, own.label, dissolve ? "dissolved" : "kept", fits, covered, rel, test.chi2_static,
      test.chi2_own, test.Statistic(), test.threshold, test.dof, test.landmarks, test.frames,
      test.offset_static_px, test.offset_own_px);
  return dissolve;
}

}  // namespace

MovingTestResult TestClusterMoving(const PointTracks& tracks, const std::vector<int>& labels,
                                   const MotionEstimate& estimate, int label,
                                   const MovingTestOptions& options) {
  const std::vector<Model> models = ModelsOf(estimate);
  const Model* world = nullptr;
  const Model* own = nullptr;
  for (const Model& m : models) {
    if (m.label == 0) world = &m;
    if (m.label == label) own = &m;
  }
  if (!world || !own || label == 0) return {};
  return TestModel(tracks, labels, *world, *own, options);
}

int DissolveUnsupportedClusters(const PointTracks& tracks, const ModelAssignmentOptions& options,
                                MotionEstimate* estimate) {
  const std::vector<Model> models = ModelsOf(*estimate);
  if (models.empty() || models[0].label != 0) return 0;
  const Model& world = models[0];
  std::vector<int>& labels = estimate->landmark_cluster;
  const int n = static_cast<int>(std::min(labels.size(), tracks.size()));
  std::set<int> removed;
  for (const Model& m : models) {
    if (m.label == 0) continue;
    int covered = 0, fits = 0;
    for (int l = 0; l < n; ++l) {
      if (labels[l] != m.label || static_cast<int>(tracks[l].samples.size()) < kMinSamples) continue;
      const double c = CostUnder(tracks[l], Informations(tracks[l]), m, options.min_coverage,
                                 options.max_dropped_samples, options.sample_gate_chi2);
      if (c < 0) continue;
      ++covered;
      fits += c <= options.fit_threshold;
    }
    const bool dissolve =
        ShouldDissolve("final check", fits, covered, tracks, labels, *estimate, &world, m, options);
    if (dissolve) removed.insert(m.label);
  }
  if (removed.empty()) return 0;
  for (int l = 0; l < n; ++l) {
    if (!removed.count(labels[l])) continue;
    labels[l] = -1;
    estimate->landmark_in_cluster[l] = Eigen::Vector3d::Constant(NAN);
    if (static_cast<int>(tracks[l].samples.size()) < kMinSamples) continue;
    Eigen::Vector3d in_world;
    const double c = CostUnder(tracks[l], Informations(tracks[l]), world, options.min_coverage,
                               options.max_dropped_samples, options.sample_gate_chi2, &in_world);
    if (c < 0 || c > options.fit_threshold) continue;
    labels[l] = 0;
    estimate->landmark_in_cluster[l] = in_world;
  }
  std::erase_if(estimate->clusters,
                [&](const ClusterMotion& c) { return removed.count(c.cluster) > 0; });
  return static_cast<int>(removed.size());
}

ModelAssignment AssignToMotionModels(const PointTracks& tracks, const std::vector<int>& labels,
                                     const MotionEstimate& estimate,
                                     const ModelAssignmentOptions& options,
                                     std::vector<int>* reclusterings) {
  ModelAssignment out;
  out.labels = labels;
  out.labels.resize(tracks.size(), -1);
  const std::vector<Model> models = ModelsOf(estimate);
  if (models.empty()) return out;
  const int num_models = static_cast<int>(models.size());
  const int num_landmarks = static_cast<int>(tracks.size());
  auto label_of = [&](int l) { return l < static_cast<int>(labels.size()) ? labels[l] : -1; };

  // Costs of every testable landmark under every model (-1: not covered).
  std::vector<double> cost(static_cast<size_t>(num_landmarks) * num_models, -1.0);
  auto cost_at = [&](int l, int m) -> double& { return cost[static_cast<size_t>(l) * num_models + m]; };
  std::vector<char> testable(num_landmarks, 0);
  std::map<int, int> model_index;
  for (int m = 0; m < num_models; ++m) model_index[models[m].label] = m;
  for (int l = 0; l < num_landmarks; ++l) {
    if (static_cast<int>(tracks[l].samples.size()) < kMinSamples) continue;
    testable[l] = 1;
    const std::vector<Eigen::Matrix3d> info = Informations(tracks[l]);
    for (int m = 0; m < num_models; ++m)
      cost_at(l, m) = CostUnder(tracks[l], info, models[m], options.min_coverage,
                                options.max_dropped_samples, options.sample_gate_chi2);
  }

  // Clusters that have not earned their existence (see the header).
  std::map<int, int> own_covered, own_fits;
  for (int l = 0; l < num_landmarks; ++l) {
    const int label = label_of(l);
    if (!testable[l] || label < 1) continue;
    const auto it = model_index.find(label);
    if (it == model_index.end()) continue;
    const double c = cost_at(l, it->second);
    if (c < 0) continue;
    ++own_covered[label];
    own_fits[label] += c <= options.fit_threshold;
  }
  std::vector<char> dissolved(num_models, 0);
  for (int m = 0; m < num_models; ++m) {
    const int label = models[m].label;
    if (label == 0) continue;
    const bool dissolve = ShouldDissolve("model assignment", own_fits[label],
                                         own_covered[label], tracks, labels, estimate,
                                         models[0].label == 0 ? &models[0] : nullptr,
                                         models[m], options);
    if (!dissolve) continue;
    dissolved[m] = 1;
    ++out.dissolved;
  }
  std::map<int, bool> is_dissolved;
  for (int m = 0; m < num_models; ++m)
    if (dissolved[m]) is_dissolved[models[m].label] = true;

  // Per-cluster statistics for the merge test: own cost, and cost/fit under every other model.
  struct Under {
    int covered = 0;
    int fits = 0;
    double sum = 0.0;
  };
  std::map<int, int> members;           // landmarks with >= 4 samples per surviving label
  std::map<int, Under> own;             // under the cluster's own model
  std::map<int, std::map<int, Under>> other;

  for (int l = 0; l < num_landmarks; ++l) {
    const int input = label_of(l);
    const bool from_dissolved = input >= 1 && is_dissolved.count(input);
    if (!testable[l]) {
      if (from_dissolved) out.labels[l] = -1;
      continue;
    }
    const int label = from_dissolved ? -1 : input;  // a dissolved cluster has no statistics
    int best = -1;
    double best_score = std::numeric_limits<double>::infinity(), best_cost = 0.0;
    for (int m = 0; m < num_models; ++m) {
      const double c = cost_at(l, m);
      if (c < 0 || dissolved[m]) continue;
      const int favoured = options.favour_own_label && label >= 0 ? label : 0;
      const double score = c + (models[m].label != favoured ? options.static_margin : 0.0);
      if (score < best_score) best_score = score, best = models[m].label, best_cost = c;
      if (label < 0) continue;
      Under& u = models[m].label == label ? own[label] : other[label][models[m].label];
      ++u.covered;
      u.sum += c;
      if (c <= options.fit_threshold) ++u.fits;
    }
    if (label >= 0) ++members[label];
    if (best < 0) {  // no model covers the track: keep what it had
      if (from_dissolved) out.labels[l] = -1;
      continue;
    }
    if (best_cost > options.fit_threshold) {
      out.labels[l] = -1;
      // Re-clustered, unless it was already handed out max_reclusterings times: then every
      // group it was put in was dissolved, and re-clustering it again would rebuild the group.
      int* times = reclusterings && l < static_cast<int>(reclusterings->size())
                       ? &(*reclusterings)[l] : nullptr;
      if (times && *times >= options.max_reclusterings) {
        ++out.unexplained;
      } else {
        out.outliers.push_back(l);
        if (times) ++*times;
      }
      continue;
    }
    if (best != input) ++out.reassigned;
    out.labels[l] = best;
  }

  // Merges: p into the model q that explains p's landmarks about as well as p's own; only
  // into a bigger cluster (the static one first), so no cycles.
  std::map<int, int> into;
  for (const auto& [p, n] : members) {
    if (p == 0) continue;
    const Under& o = own[p];
    const double own_mean = o.covered > 0 ? o.sum / o.covered : std::numeric_limits<double>::infinity();
    int target = -1;
    double target_mean = std::numeric_limits<double>::infinity();
    for (const auto& [q, u] : other[p]) {
      if (members[q] < n || (members[q] == n && q > p)) continue;
      if (u.covered < options.merge_fraction * n || u.fits < options.merge_fraction * u.covered)
        continue;
      if (q != 0 && options.split_gap_m > 0 && ApartInTheWorld(estimate, p, q, options.split_gap_m))
        continue;
      const double mean = u.sum / u.covered;
      if (mean > std::max(options.merge_ratio * own_mean, own_mean + options.merge_slack)) continue;
      if (q == 0 || (target != 0 && mean < target_mean)) target = q, target_mean = mean;
    }
    if (target >= 0) into[p] = target;
  }
  out.merges = static_cast<int>(into.size());
  for (int& x : out.labels) {
    for (int hops = 0; x >= 0 && hops < static_cast<int>(into.size()); ++hops) {
      auto it = into.find(x);
      if (it == into.end()) break;
      x = it->second;
    }
  }
  return out;
}

}  // namespace cslam
