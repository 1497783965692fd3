#include "backend/hac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace cslam {

void HacOptions::Check() const {
  CheckOption(std::isfinite(epsilon), "epsilon", "must be a finite number", epsilon);
  CheckOption(max_dense_items >= 0 && max_dense_items <= 16384, "max_dense_items",
              "must be in [0, 16384]", max_dense_items);
}

void HacOptions::Load(OptionsReader& reader) {
  reader.Read("epsilon", &epsilon);
  reader.Read("max_dense_items", &max_dense_items);
}

namespace {

// Open-addressing map from a non-negative int to a double (linear probing, backward-shift
// deletion, load factor <= 3/4): the per-cluster linkage rows. std::unordered_map costs an
// allocation per entry, which dominated the run time. The rows hold every distance twice and
// were the largest allocation of a cold window; 3/4 instead of 1/2 takes a third off them.
class LinkageRow {
 public:
  void Reserve(size_t n) {
    size_t cap = 8;
    while (3 * cap < 4 * n) cap <<= 1;
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
    if (4 * (size_ + 1) > 3 * keys_.size()) Rehash(std::max<size_t>(8, 2 * keys_.size()));
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

// Heap entry: a lower bound `d` on the smallest linkage of cluster `a` (its nearest-neighbour
// distance when computed). std heap functions build a max-heap: "Later" puts the smallest
// (d, a) on top.
struct HeapEntry {
  double d;
  int a;
};
inline bool Later(const HeapEntry& x, const HeapEntry& y) {
  if (x.d != y.d) return x.d > y.d;
  return x.a > y.a;
}

// Each cluster's recorded nearest neighbour and the heap of those within ε, with lazy
// deletion: an entry is stale once its cluster merged away or was rescanned since.
class NearestNeighbourHeap {
 public:
  explicit NearestNeighbourHeap(int n, double eps) : nn_(n, -1), nn_d_(n, 0.0), eps_(eps) {}
  void Record(int a, int best, double best_d) {
    nn_[a] = best;
    nn_d_[a] = best_d;
    if (best >= 0 && best_d <= eps_) {
      heap_.push_back({best_d, a});
      std::push_heap(heap_.begin(), heap_.end(), Later);
    }
  }
  // The smallest entry that is still current, or false when none is left.
  bool Pop(const std::vector<char>& active, HeapEntry* top) {
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), Later);
      *top = heap_.back();
      heap_.pop_back();
      if (active[top->a] && top->d == nn_d_[top->a]) return true;
    }
    return false;
  }
  int neighbour(int a) const { return nn_[a]; }

 private:
  std::vector<int> nn_;
  std::vector<double> nn_d_;
  std::vector<HeapEntry> heap_;
  double eps_;
};

// Every item starts as its own cluster, all active.
struct MergeForest {
  explicit MergeForest(int n) : parent(n), active(n, 1) {
    for (int i = 0; i < n; ++i) parent[i] = i;
  }
  void Absorb(int keep, int gone) {
    active[gone] = 0;
    parent[gone] = keep;
  }
  std::vector<int> parent;  // merged item → the cluster that absorbed it
  std::vector<char> active;
};

// Dense engine for small n: the same algorithm on an n×n array (NaN = undefined), where a
// merge is two linear passes instead of hash updates.
// Frees `entries` (when given) once the engine no longer reads them.
void Release(std::vector<DistanceEntry>* entries) {
  if (entries) std::vector<DistanceEntry>().swap(*entries);
}

std::vector<int> DenseHac(const SparseDistances& distances, double eps,
                          std::vector<DistanceEntry>* release) {
  const int n = distances.size();
  const double kNone = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> dm(static_cast<size_t>(n) * n, kNone);
  auto at = [&](int a, int b) -> double& { return dm[static_cast<size_t>(a) * n + b]; };
  for (const auto& e : distances.entries) {
    if (std::isnan(e.d) || e.a == e.b) continue;
    double& v = at(e.a, e.b);
    v = std::isnan(v) ? e.d : std::max(v, e.d);
    at(e.b, e.a) = v;
  }
  Release(release);
  NearestNeighbourHeap heap(n, eps);
  auto rescan = [&](int a) {
    int best = -1;
    double best_d = 0;
    const double* row = &dm[static_cast<size_t>(a) * n];
    for (int b = 0; b < n; ++b)
      if (!std::isnan(row[b]) && (best < 0 || row[b] < best_d)) best = b, best_d = row[b];
    heap.Record(a, best, best_d);
  };
  for (int a = 0; a < n; ++a) rescan(a);
  MergeForest forest(n);
  HeapEntry top;
  while (heap.Pop(forest.active, &top)) {
    const int a = top.a;
    const int b = heap.neighbour(a);
    if (b < 0 || !forest.active[b] || at(a, b) != top.d) {
      rescan(a);
      continue;
    }
    const int keep = std::min(a, b), gone = std::max(a, b);
    double* row_keep = &dm[static_cast<size_t>(keep) * n];
    double* row_gone = &dm[static_cast<size_t>(gone) * n];
    for (int c = 0; c < n; ++c) {
      const double dg = row_gone[c];
      if (c != keep && !std::isnan(dg) && !(row_keep[c] >= dg)) row_keep[c] = at(c, keep) = dg;
      row_gone[c] = kNone;
      at(c, gone) = kNone;
    }
    row_keep[gone] = kNone;
    forest.Absorb(keep, gone);
    rescan(keep);
  }
  return forest.parent;
}

std::vector<int> SparseHac(const SparseDistances& distances, double eps,
                           std::vector<DistanceEntry>* release) {
  const int n = distances.size();
  std::vector<LinkageRow> rows(n);
  {
    std::vector<int> degree(n, 0);
    for (const auto& e : distances.entries)
      if (!std::isnan(e.d) && e.a != e.b) ++degree[e.a], ++degree[e.b];
    for (int i = 0; i < n; ++i) rows[i].Reserve(degree[i]);
  }
  for (const auto& e : distances.entries) {
    if (std::isnan(e.d) || e.a == e.b) continue;
    // A duplicated entry keeps its largest value (complete linkage).
    const double* old = rows[e.a].Find(e.b);
    const double d = old ? std::max(*old, e.d) : e.d;
    rows[e.a].Set(e.b, d);
    rows[e.b].Set(e.a, d);
  }
  Release(release);

  // Nearest-neighbour heap with lazy deletion (the "generic" scheme of Müllner 2011): each
  // cluster's entry is a lower bound of its row minimum, because complete-linkage rows only
  // grow — d(A∪B, C) >= d(A,C), d(B,C), and a new neighbour A∪B of C replaces B at a value
  // >= d(B,C). An entry is trusted only when its recorded neighbour still has that exact
  // linkage; otherwise the row is rescanned. Rows above ε never enter the heap.
  NearestNeighbourHeap heap(n, eps);
  auto rescan = [&](int a) {
    int best = -1;
    double best_d = 0;
    rows[a].ForEach([&](int b, double d) {
      if (best < 0 || d < best_d || (d == best_d && b < best)) best = b, best_d = d;
    });
    heap.Record(a, best, best_d);
  };
  for (int a = 0; a < n; ++a) rescan(a);

  MergeForest forest(n);
  HeapEntry top;
  while (heap.Pop(forest.active, &top)) {
    const int a = top.a;
    const int b = heap.neighbour(a);
    const double* current = b >= 0 && forest.active[b] ? rows[a].Find(b) : nullptr;
    if (!current || *current != top.d) {
      rescan(a);  // the neighbour merged or moved away: refresh the bound
      continue;
    }
    // (a, b) is the globally closest pair: every other bound in the heap is >= top.d.
    int keep = a, gone = b;
    if (rows[gone].size() > rows[keep].size()) std::swap(keep, gone);
    rows[gone].ForEach([&](int c, double d_gone) {
      if (c == keep) return;
      rows[c].Erase(gone);
      double* d_keep = rows[keep].Find(c);
      if (d_keep) {
        if (d_gone > *d_keep) {
          *d_keep = d_gone;
          rows[c].Set(keep, d_gone);
        }
      } else {
        rows[keep].Set(c, d_gone);
        rows[c].Set(keep, d_gone);
      }
    });
    rows[keep].Erase(gone);
    rows[gone].Clear();
    forest.Absorb(keep, gone);
    rescan(keep);
  }
  return forest.parent;
}

std::vector<int> Hac(const SparseDistances& distances, const HacOptions& options,
                     std::vector<DistanceEntry>* release) {
  const int n = distances.size();
  const std::vector<int> parent = n <= options.max_dense_items
                                      ? DenseHac(distances, options.epsilon, release)
                                      : SparseHac(distances, options.epsilon, release);
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

}  // namespace

std::vector<int> CompleteLinkageHac(const SparseDistances& distances, const HacOptions& options) {
  return Hac(distances, options, nullptr);
}

std::vector<int> CompleteLinkageHac(SparseDistances&& distances, const HacOptions& options) {
  return Hac(distances, options, &distances.entries);
}

}  // namespace cslam
