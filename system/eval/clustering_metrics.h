#pragma once
// Clustering quality against ground-truth labels (clusterslam_spec.md §9).
// Labels are arbitrary integers; a predicted label < 0 means "not clustered". Both vectors
// must have the same length (one entry per landmark).
#include <utility>
#include <vector>

namespace cslam {

/// Best one-to-one matching of predicted to true labels (Hungarian on the contingency table)
/// divided by the number of entries. Entries with predicted < 0 are never matched, so they
/// count as errors; predicted clusters left without a partner count as errors too. NaN for
/// empty input.
double ClusteringAccuracy(const std::vector<int>& truth, const std::vector<int>& predicted);

/// Variation of information H(X|Y) + H(Y|X) = H(X) + H(Y) − 2 I(X;Y), natural logarithm
/// (nats). Every predicted < 0 entry is its own singleton cluster (an unclustered landmark
/// shares nothing with any other). 0 for identical partitions up to relabelling; NaN for
/// empty input.
double VariationOfInformation(const std::vector<int>& truth, const std::vector<int>& predicted);

/// The Hungarian matching behind ClusteringAccuracy as (truth label, predicted label) pairs,
/// sorted by truth label; only pairs that share at least one entry are returned. Predicted
/// labels < 0 are never matched.
std::vector<std::pair<int, int>> MatchClusters(const std::vector<int>& truth,
                                               const std::vector<int>& predicted);

}  // namespace cslam
