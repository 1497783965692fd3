#pragma once
// Complete-linkage hierarchical agglomerative clustering on a sparse distance matrix
// (clusterslam_spec.md §4). Complete linkage because motion consistency is not transitive.
#include <vector>

#include "backend/motion_distance.h"
#include "core/options_reader.h"

namespace cslam {

/// Threshold of the agglomeration.
struct HacOptions {
  double epsilon = 60.0;  ///< stop when the closest cluster pair is farther than this (Eq. 1
                          ///< units); 60 indoor, 90 outdoor [paper]
  int max_dense_items = 2048;  ///< performance only (same result): up to this many items use
                               ///< an n×n array (8 n² bytes), above it hashed sparse rows
  void Check() const;
  void Load(OptionsReader& reader);
};

/// Clusters the `distances.size()` items; returns a label per item, 0..K-1 numbered by each
/// cluster's smallest item. Linkage = the maximum dᵢⱼ over the VALID member pairs
/// [ours]; two clusters without any valid pair are never merged directly, so an invalid
/// entry never bridges two groups; d(A∪B, C) = max(d(A,C), d(B,C)) over the defined terms.
/// Ties are broken by (distance, smaller cluster id) so the result is deterministic.
/// Cost: O(m log m) heap work for the m valid entries at most ε plus O(n) hash updates per
/// merge, O(n² log n) in the worst case.
std::vector<int> CompleteLinkageHac(const SparseDistances& distances, const HacOptions& options);
/// The same, releasing the distance list once the engine has its own copy of it: a cold window
/// of ~2 500 landmarks holds ~2 M entries, and the two copies were the run's memory peak.
std::vector<int> CompleteLinkageHac(SparseDistances&& distances, const HacOptions& options);

}  // namespace cslam
