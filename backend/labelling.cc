#include "backend/labelling.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace cslam {

double LabellingVariation(const std::vector<int>& a, const std::vector<int>& b) {
  const size_t n = std::max(a.size(), b.size());
  auto at = [](const std::vector<int>& v, size_t i) { return i < v.size() ? v[i] : -1; };
  std::map<std::pair<int, int>, double> joint;
  std::map<int, double> pa, pb;
  double total = 0;
  for (size_t i = 0; i < n; ++i) {
    const int x = at(a, i), y = at(b, i);
    if (x < 0 && y < 0) continue;
    joint[{x, y}] += 1, pa[x] += 1, pb[y] += 1, total += 1;
  }
  if (total == 0) return 0.0;
  // VI = Σ p(x,y) [log(p(x)/p(x,y)) + log(p(y)/p(x,y))].
  double vi = 0;
  for (const auto& [xy, c] : joint) vi += c / total * (std::log(pa[xy.first] / c) + std::log(pb[xy.second] / c));
  return std::max(0.0, vi);
}

std::vector<int> StaticFirstLabels(const std::vector<int>& labels,
                                   const std::vector<int>& observations,
                                   const std::vector<int>* previous_static) {
  const int num_labels = labels.empty() ? 0 : *std::max_element(labels.begin(), labels.end()) + 1;
  std::vector<long> obs(num_labels, 0), overlap(num_labels, 0);
  std::vector<int> first(num_labels, -1);
  bool have_previous = false;
  for (size_t i = 0; i < labels.size(); ++i) {
    const int k = labels[i];
    if (k < 0) continue;
    obs[k] += i < observations.size() ? observations[i] : 0;
    if (first[k] < 0) first[k] = static_cast<int>(i);
    if (previous_static && i < previous_static->size() && (*previous_static)[i] == 0) {
      ++overlap[k];
      have_previous = true;
    }
  }
  std::vector<int> order;
  for (int k = 0; k < num_labels; ++k)
    if (first[k] >= 0) order.push_back(k);
  auto by_observations = [&](int x, int y) {
    if (obs[x] != obs[y]) return obs[x] > obs[y];
    return first[x] < first[y];
  };
  std::sort(order.begin(), order.end(), by_observations);
  if (have_previous && !order.empty()) {
    auto stat = std::min_element(order.begin(), order.end(), [&](int x, int y) {
      if (overlap[x] != overlap[y]) return overlap[x] > overlap[y];
      return by_observations(x, y);
    });
    std::rotate(order.begin(), stat, stat + 1);
  }
  std::vector<int> new_id(num_labels, -1);
  for (size_t r = 0; r < order.size(); ++r) new_id[order[r]] = static_cast<int>(r);
  std::vector<int> out(labels.size(), -1);
  for (size_t i = 0; i < labels.size(); ++i)
    if (labels[i] >= 0) out[i] = new_id[labels[i]];
  return out;
}

}  // namespace cslam
