#pragma once
// Small operations on landmark labellings ([landmark id] → cluster, -1 = none) used by the
// outer loop of ClusterSLAM: comparison up to relabelling and the static-cluster rule.
#include <vector>

namespace cslam {

/// Variation of information between two labellings of the same landmarks (for the outer
/// loop's convergence test; system/eval/clustering_metrics.h has the evaluation metric):
/// β_VI = H(A) + H(B) − 2 I(A;B), natural log, over the indices where at least one labelling
/// is >= 0 (-1 counts as one more class). 0 iff the partitions are equal up to relabelling.
double LabellingVariation(const std::vector<int>& a, const std::vector<int>& b);

/// Relabels `labels` (any ids >= 0, -1 kept) so the static cluster becomes 0 and the others
/// 1..K by decreasing observation count (ties: smallest landmark id). Static [ours]: without
/// `previous_static` (nullptr or no landmark labelled 0 in it), the cluster with the most
/// observations; otherwise the cluster holding most landmarks of the previous static cluster
/// (label 0 of `previous_static`), ties by observations. `observations[i]` = the number of
/// observations of landmark i.
std::vector<int> StaticFirstLabels(const std::vector<int>& labels,
                                   const std::vector<int>& observations,
                                   const std::vector<int>* previous_static = nullptr);

}  // namespace cslam
