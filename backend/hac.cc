#include "backend/hac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace cslam {

void HacOptions::Check() const {
  CheckOption(std::isfinite(epsilon), "hac.epsilon", "must be a finite number", epsilon);
}

void HacOptions::Load(OptionsReader& reader) { reader.Read("epsilon", &epsilon); }

namespace {

// Open-addressing map from a non-negative int to a double (linear probing, backward-shift
// deletion, load factor <= 1/2): the per-cluster linkage rows. std::unordered_map costs an
// allocation per entry, which dominated the run time.
class LinkageRow {
 public:
  void Reserve(size_t n) {
    size_t cap = 8;
    while (cap < 2 * n) cap <<= 1;
    if (cap > keys_.size()) Rehash(cap);
  }
  size_t size() const { return size_; }
  double* Find(int key) {
    if (keys_.empty()) return nullptr;
    for (size_t i = Slot(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return &values_[i];
      if (keys_[i] < 0) return nullptr;
    }
  }
  void Set(int key, double value) {
    if (2 * (size_ + 1) > keys_.size()) Rehash(std::max<size_t>(8, 2 * keys_.size()));
    size_t i = Slot(key);
    for (; keys_[i] >= 0; i = (i + 1) & mask_) {
      if (keys_[i] == key) {
        values_[i] = value;
        return;
      }
    }
    keys_[i] = key;
    values_[i] = value;
    ++size_;
  }
  void Erase(int key) {
    if (keys_.empty()) return;
    size_t i = Slot(key);
    for (; keys_[i] != key; i = (i + 1) & mask_)
      if (keys_[i] < 0) return;
    // Backward shift: move later members of the probe run into the hole.
    for (size_t j = (i + 1) & mask_; keys_[j] >= 0; j = (j + 1) & mask_) {
      const size_t home = Slot(keys_[j]);
      if (((j - home) & mask_) >= ((j - i) & mask_)) {
        keys_[i] = keys_[j];
        values_[i] = values_[j];
        i = j;
      }
    }
    keys_[i] = -1;
    --size_;
  }
  void Clear() {
    keys_.clear();
    values_.clear();
    keys_.shrink_to_fit();
    values_.shrink_to_fit();
    size_ = 0;
  }
  template <typename F>
  void ForEach(F&& f) const {
    for (size_t i = 0; i < keys_.size(); ++i)
      if (keys_[i] >= 0) f(keys_[i], values_[i]);
  }

 private:
  size_t Slot(int key) const {
    return static_cast<size_t>((static_cast<uint32_t>(key) * 2654435769u) >> 7) & mask_;
  }
  void Rehash(size_t cap) {
    std::vector<int> keys(cap, -1);
    std::vector<double> values(cap);
    std::swap(keys, keys_);
    std::swap(values, values_);
    mask_ = cap - 1;
    size_ = 0;
    for (size_t i = 0; i < keys.size(); ++i)
      if (keys[i] >= 0) Set(keys[i], values[i]);
  }
  std::vector<int> keys_;
  std::vector<double> values_;
  size_t mask_ = 0;
  size_t size_ = 0;
};

struct HeapEntry {
  double d;
  int a, b;  // a < b
};
// std heap functions build a max-heap: "greater" puts the smallest (d, a, b) on top.
inline bool Later(const HeapEntry& x, const HeapEntry& y) {
  if (x.d != y.d) return x.d > y.d;
  if (x.a != y.a) return x.a > y.a;
  return x.b > y.b;
}

}  // namespace

std::vector<int> CompleteLinkageHac(const SparseDistances& distances, const HacOptions& options) {
  const int n = distances.size();
  const double eps = options.epsilon;
  std::vector<LinkageRow> rows(n);
  {
    std::vector<int> degree(n, 0);
    for (const auto& e : distances.entries)
      if (!std::isnan(e.d) && e.a != e.b) ++degree[e.a], ++degree[e.b];
    for (int i = 0; i < n; ++i) rows[i].Reserve(degree[i]);
  }
  std::vector<HeapEntry> heap;
  for (const auto& e : distances.entries) {
    if (std::isnan(e.d) || e.a == e.b) continue;
    // A duplicated entry keeps its largest value (complete linkage).
    const double* old = rows[e.a].Find(e.b);
    const double d = old ? std::max(*old, e.d) : e.d;
    rows[e.a].Set(e.b, d);
    rows[e.b].Set(e.a, d);
    // Linkages only grow, so a pair above ε now can never merge: keep it out of the heap.
    if (d <= eps) heap.push_back({d, std::min(e.a, e.b), std::max(e.a, e.b)});
  }
  std::make_heap(heap.begin(), heap.end(), Later);

  std::vector<int> parent(n);  // merged item → the cluster that absorbed it
  for (int i = 0; i < n; ++i) parent[i] = i;
  std::vector<char> active(n, 1);
  auto push = [&](int x, int y, double d) {
    if (d > eps) return;
    heap.push_back({d, std::min(x, y), std::max(x, y)});
    std::push_heap(heap.begin(), heap.end(), Later);
  };

  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), Later);
    const HeapEntry top = heap.back();
    heap.pop_back();
    if (!active[top.a] || !active[top.b]) continue;
    const double* current = rows[top.a].Find(top.b);
    if (!current || *current != top.d) continue;  // stale: the linkage has grown since
    // Merge the smaller row into the larger one: fewer hash updates.
    int keep = top.a, gone = top.b;
    if (rows[gone].size() > rows[keep].size()) std::swap(keep, gone);
    rows[gone].ForEach([&](int c, double d_gone) {
      if (c == keep) return;
      rows[c].Erase(gone);
      double* d_keep = rows[keep].Find(c);
      if (d_keep) {
        if (d_gone > *d_keep) {
          *d_keep = d_gone;
          rows[c].Set(keep, d_gone);
          push(keep, c, d_gone);
        }
      } else {
        rows[keep].Set(c, d_gone);
        rows[c].Set(keep, d_gone);
        push(keep, c, d_gone);
      }
    });
    rows[keep].Erase(gone);
    rows[gone].Clear();
    active[gone] = 0;
    parent[gone] = keep;
  }

  // Number clusters by their smallest item.
  std::vector<int> labels(n, -1), root_label(n, -1);
  int next = 0;
  for (int i = 0; i < n; ++i) {
    int r = i;
    while (parent[r] != r) r = parent[r];
    if (root_label[r] < 0) root_label[r] = next++;
    labels[i] = root_label[r];
  }
  return labels;
}

}  // namespace cslam
