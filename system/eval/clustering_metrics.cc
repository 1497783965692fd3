#include "system/eval/clustering_metrics.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/errors.h"
#include "system/eval/hungarian.h"

namespace cslam {

namespace {

// Counts of (truth label, predicted label) over entries with predicted >= 0, with the sorted
// label lists that index its rows and columns.
struct Contingency {
  std::vector<int> truth_labels, predicted_labels;
  Eigen::MatrixXd counts;
};

int IndexOf(const std::vector<int>& sorted, int label) {
  return int(std::lower_bound(sorted.begin(), sorted.end(), label) - sorted.begin());
}

std::vector<int> SortedUnique(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

Contingency BuildContingency(const std::vector<int>& truth, const std::vector<int>& predicted) {
  CSLAM_CHECK(truth.size() == predicted.size(),
              "clustering metrics need one predicted label per truth label");
  Contingency c;
  c.truth_labels = SortedUnique(truth);
  std::vector<int> clustered;
  for (int p : predicted) {
    if (p >= 0) {
      clustered.push_back(p);
    }
  }
  c.predicted_labels = SortedUnique(clustered);
  c.counts = Eigen::MatrixXd::Zero(Eigen::Index(c.truth_labels.size()),
                                   Eigen::Index(c.predicted_labels.size()));
  for (size_t k = 0; k < truth.size(); ++k) {
    if (predicted[k] >= 0) {
      c.counts(IndexOf(c.truth_labels, truth[k]), IndexOf(c.predicted_labels, predicted[k])) += 1.0;
    }
  }
  return c;
}

}  // namespace

double ClusteringAccuracy(const std::vector<int>& truth, const std::vector<int>& predicted) {
  const Contingency c = BuildContingency(truth, predicted);
  if (truth.empty()) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Assignment a = SolveAssignment(c.counts, AssignmentObjective::kMaximise);
  return a.total / double(truth.size());
}

double VariationOfInformation(const std::vector<int>& truth, const std::vector<int>& predicted) {
  CSLAM_CHECK(truth.size() == predicted.size(),
              "clustering metrics need one predicted label per truth label");
  if (truth.empty()) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Unclustered entries become fresh labels below every real one, one each.
  std::vector<int> y = predicted;
  int next_singleton = -1;
  for (int& label : y) {
    if (label < 0) {
      label = next_singleton--;
    }
  }
  std::map<int, double> nx, ny;
  std::map<std::pair<int, int>, double> nxy;
  for (size_t k = 0; k < truth.size(); ++k) {
    nx[truth[k]] += 1;
    ny[y[k]] += 1;
    nxy[{truth[k], y[k]}] += 1;
  }
  // VI = −Σ p_xy [log(p_xy / p_x) + log(p_xy / p_y)].
  const double n = double(truth.size());
  double vi = 0;
  for (const auto& [xy, count] : nxy) {
    vi -= count / n * (std::log(count / nx[xy.first]) + std::log(count / ny[xy.second]));
  }
  return std::max(vi, 0.0);
}

std::vector<std::pair<int, int>> MatchClusters(const std::vector<int>& truth,
                                               const std::vector<int>& predicted) {
  const Contingency c = BuildContingency(truth, predicted);
  const Assignment a = SolveAssignment(c.counts, AssignmentObjective::kMaximise);
  std::vector<std::pair<int, int>> out;
  for (size_t r = 0; r < c.truth_labels.size(); ++r) {
    const int col = a.row_to_col[r];
    if (col >= 0 && c.counts(Eigen::Index(r), col) > 0) {
      out.emplace_back(c.truth_labels[r], c.predicted_labels[size_t(col)]);
    }
  }
  return out;
}

}  // namespace cslam
