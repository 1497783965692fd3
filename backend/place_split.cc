#include "backend/place_split.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace cslam {
namespace {

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::vector<int> GroupsByGap(const std::vector<Eigen::Vector3d>& points, double gap_m) {
  const int n = static_cast<int>(points.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const double gap2 = gap_m * gap_m;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if ((points[i] - points[j]).squaredNorm() < gap2) parent[Find(parent, i)] = Find(parent, j);
  std::map<int, int> size;
  for (int i = 0; i < n; ++i) ++size[Find(parent, i)];
  std::vector<std::pair<int, int>> by_size;  // (−size, root): largest first, ties by root
  for (const auto& [root, count] : size) by_size.emplace_back(-count, root);
  std::sort(by_size.begin(), by_size.end());
  std::map<int, int> index;
  for (size_t g = 0; g < by_size.size(); ++g) index[by_size[g].second] = static_cast<int>(g);
  std::vector<int> group(n);
  for (int i = 0; i < n; ++i) group[i] = index[Find(parent, i)];
  return group;
}

bool SeparatedByGap(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                    double gap_m) {
  const double gap2 = gap_m * gap_m;
  for (const Eigen::Vector3d& p : a)
    for (const Eigen::Vector3d& q : b)
      if ((p - q).squaredNorm() < gap2) return false;
  return true;
}

int SplitClustersByPlace(double gap_m, int min_landmarks, MotionEstimate* estimate) {
  if (!(gap_m > 0)) return 0;
  std::vector<int>& labels = estimate->landmark_cluster;
  const int n = static_cast<int>(std::min(labels.size(), estimate->landmark_in_cluster.size()));
  int next_label = 1;
  for (const ClusterMotion& c : estimate->clusters) next_label = std::max(next_label, c.cluster + 1);
  std::vector<ClusterMotion> added;
  for (const ClusterMotion& c : estimate->clusters) {
    std::vector<int> ids;
    std::vector<Eigen::Vector3d> points;
    for (int l = 0; l < n; ++l)
      if (labels[l] == c.cluster && estimate->landmark_in_cluster[l].allFinite()) {
        ids.push_back(l);
        points.push_back(estimate->landmark_in_cluster[l]);
      }
    const std::vector<int> group = GroupsByGap(points, gap_m);
    const int groups = group.empty() ? 0 : *std::max_element(group.begin(), group.end()) + 1;
    if (groups < 2) continue;
    std::vector<int> count(groups, 0);
    for (int g : group) ++count[g];
    // Groups too small to stand as a body stay where they were: a far car's few noisy points
    // are not evidence of a second body.
    std::vector<int> label_of(groups, c.cluster);
    for (int g = 1; g < groups; ++g)
      if (count[g] >= min_landmarks) {
        label_of[g] = next_label++;
        ClusterMotion copy = c;
        copy.cluster = label_of[g];
        added.push_back(std::move(copy));
      }
    for (size_t k = 0; k < ids.size(); ++k) labels[ids[k]] = label_of[group[k]];
  }
  for (ClusterMotion& c : added) estimate->clusters.push_back(std::move(c));
  return static_cast<int>(added.size());
}

}  // namespace cslam
