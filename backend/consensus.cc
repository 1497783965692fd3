#include "backend/consensus.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace cslam {

void ConsensusOptions::Check() const {
  CheckOption(chunk_length >= 2, "chunk_length", "must be >= 2 frames", chunk_length);
  CheckOption(chunk_overlap >= 0 && chunk_overlap < chunk_length, "chunk_overlap",
              "must be in [0, chunk_length)", chunk_overlap);
  CheckOption(link_overlap > 0 && link_overlap <= 1, "link_overlap",
              "must be in (0, 1]", link_overlap);
  CheckOption(max_iterations >= 1, "max_iterations", "must be >= 1", max_iterations);
  CheckOption(min_cluster_size >= 1, "min_cluster_size", "must be >= 1",
              min_cluster_size);
}

void ConsensusOptions::Load(OptionsReader& reader) {
  reader.Read("chunk_length", &chunk_length);
  reader.Read("chunk_overlap", &chunk_overlap);
  reader.Read("link_overlap", &link_overlap);
  reader.Read("max_iterations", &max_iterations);
  reader.Read("min_cluster_size", &min_cluster_size);
}

std::vector<FrameRange> ChunksOf(FrameRange range, const ConsensusOptions& options) {
  std::vector<FrameRange> chunks =
      SplitIntoChunks(range.size(), options.chunk_length, options.chunk_overlap);
  for (auto& c : chunks) c.begin += range.begin, c.end += range.begin;
  return chunks;
}

namespace {

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Label of the most frequent value of `values` (sorted in place); ties → the smallest.
int Majority(std::vector<int>& values) {
  std::sort(values.begin(), values.end());
  int best = -1, best_count = 0;
  for (size_t i = 0; i < values.size();) {
    size_t j = i;
    while (j < values.size() && values[j] == values[i]) ++j;
    if (static_cast<int>(j - i) > best_count) best = values[i], best_count = static_cast<int>(j - i);
    i = j;
  }
  return best;
}

}  // namespace

std::vector<int> ConsensusLabels(const std::vector<ChunkLabels>& chunks, int num_landmarks,
                                 const ConsensusOptions& options, ConsensusSummary* summary) {
  ConsensusSummary local_summary;
  ConsensusSummary& sum = summary ? *summary : local_summary;
  sum = ConsensusSummary();
  const int num_chunks = static_cast<int>(chunks.size());

  // Compact chunk labels to graph nodes: node = offset[m] + rank of the label in chunk m.
  // y[i] = (chunk, node) pairs of landmark i in chunk order: its sparse label vector.
  std::vector<int> offset(num_chunks + 1, 0);
  std::vector<std::vector<std::pair<int, int>>> y(num_landmarks);
  for (int m = 0; m < num_chunks; ++m) {
    const ChunkLabels& c = chunks[m];
    std::vector<int> distinct = c.labels;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    offset[m + 1] = offset[m] + static_cast<int>(distinct.size());
    for (size_t k = 0; k < c.landmarks.size(); ++k) {
      const int l = c.landmarks[k];
      if (l < 0 || l >= num_landmarks) continue;
      const int rank = static_cast<int>(
          std::lower_bound(distinct.begin(), distinct.end(), c.labels[k]) - distinct.begin());
      y[l].emplace_back(m, offset[m] + rank);
    }
  }
  const int num_nodes = offset[num_chunks];

  // Initial partition: union-find over chunk clusters of adjacent chunks with a mutual
  // majority of their shared landmarks.
  std::vector<int> parent(num_nodes);
  std::iota(parent.begin(), parent.end(), 0);
  for (int m = 0; m + 1 < num_chunks; ++m) {
    std::vector<std::pair<int, int>> shared;  // (node in m, node in m+1)
    for (int l = 0; l < num_landmarks; ++l) {
      int a = -1, b = -1;
      for (const auto& [chunk, node] : y[l]) {
        if (chunk == m) a = node;
        if (chunk == m + 1) b = node;
      }
      if (a >= 0 && b >= 0) shared.emplace_back(a, b);
    }
    std::vector<int> count_a(num_nodes, 0), count_b(num_nodes, 0);
    for (const auto& [a, b] : shared) ++count_a[a], ++count_b[b];
    std::sort(shared.begin(), shared.end());
    for (size_t i = 0; i < shared.size();) {
      size_t j = i;
      while (j < shared.size() && shared[j] == shared[i]) ++j;
      const auto [a, b] = shared[i];
      const double together = static_cast<double>(j - i);
      if (together >= options.link_overlap * std::max(count_a[a], count_b[b]))
        parent[Find(parent, a)] = Find(parent, b);
      i = j;
    }
  }
  std::vector<int> node_cluster(num_nodes, -1);
  int num_clusters = 0;
  {
    std::vector<int> root_id(num_nodes, -1);
    for (int v = 0; v < num_nodes; ++v) {
      const int r = Find(parent, v);
      if (root_id[r] < 0) root_id[r] = num_clusters++;
      node_cluster[v] = root_id[r];
    }
  }
  sum.initial_clusters = num_clusters;

  std::vector<int> assign(num_landmarks, -1);
  std::vector<int> scratch;
  for (int l = 0; l < num_landmarks; ++l) {
    if (y[l].empty()) continue;
    scratch.clear();
    for (const auto& [chunk, node] : y[l]) scratch.push_back(node_cluster[node]);
    assign[l] = Majority(scratch);
  }

  // IVC: (a) centres = per-chunk majority node of the members; (b) each landmark joins the
  // centre at the smallest normalised Hamming distance over the chunks both have.
  std::vector<int> centre;                          // [cluster * num_chunks + chunk] → node / -1
  std::vector<std::vector<int>> clusters_with_node;  // [node] → clusters whose centre has it
  for (int it = 0; it < options.max_iterations; ++it) {
    sum.iterations = it + 1;
    std::vector<std::tuple<int, int, int>> votes;  // (cluster, chunk, node)
    for (int l = 0; l < num_landmarks; ++l)
      for (const auto& [chunk, node] : y[l])
        if (assign[l] >= 0) votes.emplace_back(assign[l], chunk, node);
    std::sort(votes.begin(), votes.end());
    centre.assign(static_cast<size_t>(num_clusters) * num_chunks, -1);
    std::vector<int> best_count(centre.size(), 0);
    for (size_t i = 0; i < votes.size();) {
      size_t j = i;
      while (j < votes.size() && votes[j] == votes[i]) ++j;
      const auto [k, chunk, node] = votes[i];
      const size_t cell = static_cast<size_t>(k) * num_chunks + chunk;
      // Ties keep the first (smallest) node: votes are sorted by node within a cell.
      if (static_cast<int>(j - i) > best_count[cell]) best_count[cell] = static_cast<int>(j - i), centre[cell] = node;
      i = j;
    }
    clusters_with_node.assign(num_nodes, {});
    for (int k = 0; k < num_clusters; ++k)
      for (int m = 0; m < num_chunks; ++m) {
        const int node = centre[static_cast<size_t>(k) * num_chunks + m];
        if (node >= 0) clusters_with_node[node].push_back(k);
      }

    auto distance = [&](int l, int k) {
      int shared = 0, mismatch = 0;
      for (const auto& [chunk, node] : y[l]) {
        const int c = centre[static_cast<size_t>(k) * num_chunks + chunk];
        if (c < 0) continue;
        ++shared;
        mismatch += c != node;
      }
      return shared == 0 ? 2.0 : static_cast<double>(mismatch) / shared;  // 2 = undefined
    };
    bool changed = false;
    std::vector<int> next = assign;
    for (int l = 0; l < num_landmarks; ++l) {
      if (y[l].empty()) continue;
      // Only centres sharing at least one label can beat distance 1: they are the candidates.
      const int current = assign[l];
      int best = current;
      double best_d = distance(l, current);
      for (const auto& [chunk, node] : y[l])
        for (int k : clusters_with_node[node]) {
          const double d = distance(l, k);
          if (d < best_d || (d == best_d && k < best && best != current)) best = k, best_d = d;
        }
      if (best != current) changed = true;
      next[l] = best;
    }
    assign.swap(next);
    if (!changed) {
      sum.converged = true;
      break;
    }
  }

  // Drop small clusters, then number the rest by their smallest landmark id.
  std::vector<int> size(num_clusters, 0);
  for (int k : assign)
    if (k >= 0) ++size[k];
  std::vector<int> final_id(num_clusters, -1);
  int next_id = 0;
  for (int l = 0; l < num_landmarks; ++l) {
    int& k = assign[l];
    if (k < 0) continue;
    if (size[k] < options.min_cluster_size) {
      k = -1;
      ++sum.dropped_landmarks;
      continue;
    }
    if (final_id[k] < 0) final_id[k] = next_id++;
    k = final_id[k];
  }
  return assign;
}

}  // namespace cslam
