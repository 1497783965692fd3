#include "backend/model_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace cslam {

void ModelAssignmentOptions::Check() const {
  CheckOption(std::isfinite(fit_threshold) && fit_threshold > 0, "model_assignment.fit_threshold",
              "must be a reduced chi-square > 0", fit_threshold);
  CheckOption(std::isfinite(static_margin) && static_margin >= 0, "model_assignment.static_margin",
              "must be >= 0", static_margin);
  CheckOption(min_coverage > 0 && min_coverage <= 1, "model_assignment.min_coverage",
              "must be in (0, 1]", min_coverage);
  CheckOption(merge_fraction > 0 && merge_fraction <= 1, "model_assignment.merge_fraction",
              "must be in (0, 1]", merge_fraction);
  CheckOption(std::isfinite(merge_ratio) && merge_ratio >= 1, "model_assignment.merge_ratio",
              "must be >= 1", merge_ratio);
  CheckOption(std::isfinite(merge_slack) && merge_slack >= 0, "model_assignment.merge_slack",
              "must be >= 0", merge_slack);
  CheckOption(std::isfinite(outlier_alpha) && outlier_alpha >= 0, "model_assignment.outlier_alpha",
              "must be >= 0", outlier_alpha);
  CheckOption(min_outlier_cluster >= 1, "model_assignment.min_outlier_cluster", "must be >= 1",
              min_outlier_cluster);
}

void ModelAssignmentOptions::Load(OptionsReader& reader) {
  reader.Read("enabled", &enabled);
  reader.Read("fit_threshold", &fit_threshold);
  reader.Read("static_margin", &static_margin);
  reader.Read("min_coverage", &min_coverage);
  reader.Read("merge_fraction", &merge_fraction);
  reader.Read("merge_ratio", &merge_ratio);
  reader.Read("merge_slack", &merge_slack);
  reader.Read("outlier_alpha", &outlier_alpha);
  reader.Read("min_outlier_cluster", &min_outlier_cluster);
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
double CostUnder(const PointTrack& track, const std::vector<Eigen::Matrix3d>& info,
                 const Model& model, double min_coverage) {
  const auto& samples = track.samples;
  thread_local std::vector<Eigen::Vector3d> y;
  thread_local std::vector<Eigen::Matrix3d> w;
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
  const Eigen::Vector3d mean = a.ldlt().solve(b);
  double chi2 = 0.0;
  for (int k = 0; k < n; ++k) chi2 += (y[k] - mean).dot(w[k] * (y[k] - mean));
  const double cost = chi2 / (3.0 * n - 3.0);
  return std::isfinite(cost) ? cost : -1.0;
}

std::vector<Eigen::Matrix3d> Informations(const PointTrack& track) {
  std::vector<Eigen::Matrix3d> info;
  info.reserve(track.samples.size());
  for (const PointSample& s : track.samples) info.push_back(s.cov.inverse());
  return info;
}

}  // namespace

double ModelCost(const PointTrack& track, const MotionEstimate& estimate, int label,
                 double min_coverage) {
  for (const Model& m : ModelsOf(estimate))
    if (m.label == label) return CostUnder(track, Informations(track), m, min_coverage);
  return -1.0;
}

ModelAssignment AssignToMotionModels(const PointTracks& tracks, const std::vector<int>& labels,
                                     const MotionEstimate& estimate,
                                     const ModelAssignmentOptions& options) {
  ModelAssignment out;
  out.labels = labels;
  out.labels.resize(tracks.size(), -1);
  const std::vector<Model> models = ModelsOf(estimate);
  if (models.empty()) return out;

  // Per-cluster statistics for the merge test: own cost, and cost/fit under every other model.
  struct Under {
    int covered = 0;
    int fits = 0;
    double sum = 0.0;
  };
  std::map<int, int> members;           // landmarks with >= 4 samples per label
  std::map<int, Under> own;             // under the cluster's own model
  std::map<int, std::map<int, Under>> other;

  std::vector<double> cost(models.size());
  for (int l = 0; l < static_cast<int>(tracks.size()); ++l) {
    if (static_cast<int>(tracks[l].samples.size()) < kMinSamples) continue;
    const int label = l < static_cast<int>(labels.size()) ? labels[l] : -1;
    const std::vector<Eigen::Matrix3d> info = Informations(tracks[l]);
    int best = -1;
    double best_score = std::numeric_limits<double>::infinity(), best_cost = 0.0;
    for (size_t m = 0; m < models.size(); ++m) {
      cost[m] = CostUnder(tracks[l], info, models[m], options.min_coverage);
      if (cost[m] < 0) continue;
      const double score = cost[m] + (models[m].label != 0 ? options.static_margin : 0.0);
      if (score < best_score) best_score = score, best = models[m].label, best_cost = cost[m];
      if (label < 0) continue;
      Under& u = models[m].label == label ? own[label] : other[label][models[m].label];
      ++u.covered;
      u.sum += cost[m];
      if (cost[m] <= options.fit_threshold) ++u.fits;
    }
    if (label >= 0) ++members[label];
    if (best < 0) continue;  // no model covers the track: keep what it had
    if (best_cost > options.fit_threshold) {
      out.outliers.push_back(l);
      out.labels[l] = -1;
      continue;
    }
    if (best != label) ++out.reassigned;
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
