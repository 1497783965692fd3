#include "system/eval/clustering_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

namespace cslam {
namespace {

TEST(ClusteringMetrics, PermutedLabelsArePerfect) {
  const std::vector<int> truth = {0, 0, 1, 1, 1, 2, 3, 3};
  const std::vector<int> predicted = {7, 7, 2, 2, 2, 0, 5, 5};
  EXPECT_DOUBLE_EQ(ClusteringAccuracy(truth, predicted), 1.0);
  EXPECT_NEAR(VariationOfInformation(truth, predicted), 0.0, 1e-12);
  EXPECT_EQ(MatchClusters(truth, predicted),
            (std::vector<std::pair<int, int>>{{0, 7}, {1, 2}, {2, 0}, {3, 5}}));
}

TEST(ClusteringMetrics, KnownSplit) {
  // Object 0 split in two predicted clusters. Y determines X, so H(X|Y) = 0 and
  // VI = H(Y|X) = 1/2 * ln 2 (half the entries sit in an evenly split group) ≈ 0.34657.
  // Accuracy: best matching keeps 2 of object 0 and all 4 of object 1 → 6 / 8.
  const std::vector<int> truth = {0, 0, 0, 0, 1, 1, 1, 1};
  const std::vector<int> predicted = {0, 0, 1, 1, 2, 2, 2, 2};
  EXPECT_DOUBLE_EQ(ClusteringAccuracy(truth, predicted), 0.75);
  EXPECT_NEAR(VariationOfInformation(truth, predicted), 0.5 * std::log(2.0), 1e-12);
  // VI is symmetric.
  EXPECT_NEAR(VariationOfInformation(predicted, truth), 0.5 * std::log(2.0), 1e-12);
}

TEST(ClusteringMetrics, UnclusteredEntriesAreErrorsAndSingletons) {
  // Entry 2 unclustered: accuracy 5/6. Y = {0,1},{2},{3,4,5} determines X; group X=0 splits
  // 2:1, so VI = H(Y|X) = 1/2 * (−2/3 ln 2/3 − 1/3 ln 1/3) ≈ 0.318257.
  const std::vector<int> truth = {0, 0, 0, 1, 1, 1};
  const std::vector<int> predicted = {5, 5, -1, 7, 7, 7};
  EXPECT_NEAR(ClusteringAccuracy(truth, predicted), 5.0 / 6.0, 1e-15);
  const double h = -(2.0 / 3.0) * std::log(2.0 / 3.0) - (1.0 / 3.0) * std::log(1.0 / 3.0);
  EXPECT_NEAR(VariationOfInformation(truth, predicted), 0.5 * h, 1e-12);
}

TEST(ClusteringMetrics, EachUnclusteredEntryIsItsOwnCluster) {
  // Two unclustered entries are two singletons: Y = {0},{1},{2,3}, VI = H(Y) = 1.5 ln 2
  // (were they one cluster, VI would be ln 2).
  const std::vector<int> truth = {0, 0, 0, 0};
  const std::vector<int> predicted = {-1, -1, 3, 3};
  EXPECT_NEAR(VariationOfInformation(truth, predicted), 1.5 * std::log(2.0), 1e-12);
  EXPECT_DOUBLE_EQ(ClusteringAccuracy(truth, predicted), 0.5);
}

TEST(ClusteringMetrics, AllInOneClusterGivesTheLargestObjectFraction) {
  std::vector<int> truth(10, 0);
  truth[6] = truth[7] = 1;
  truth[8] = truth[9] = 2;
  const std::vector<int> predicted(10, 0);
  EXPECT_DOUBLE_EQ(ClusteringAccuracy(truth, predicted), 0.6);
}

TEST(ClusteringMetrics, MatchSkipsObjectsWithoutOverlap) {
  const std::vector<int> truth = {0, 0, 1, 1, 2};
  const std::vector<int> predicted = {9, 9, 4, 4, 4};
  EXPECT_EQ(MatchClusters(truth, predicted), (std::vector<std::pair<int, int>>{{0, 9}, {1, 4}}));
  EXPECT_DOUBLE_EQ(ClusteringAccuracy(truth, predicted), 0.8);
}

// Accuracy by enumerating every injective map of predicted labels onto truth labels.
double BruteForceAccuracy(const std::vector<int>& truth, const std::vector<int>& predicted,
                          int n_truth, int n_pred) {
  std::vector<int> target(size_t(std::max(n_truth, n_pred)));
  std::iota(target.begin(), target.end(), 0);  // values >= n_truth mean "unmatched"
  int best = 0;
  do {
    int hits = 0;
    for (size_t k = 0; k < truth.size(); ++k)
      if (predicted[k] >= 0 && target[size_t(predicted[k])] == truth[k]) ++hits;
    best = std::max(best, hits);
  } while (std::next_permutation(target.begin(), target.end()));
  return double(best) / double(truth.size());
}

TEST(ClusteringMetrics, AccuracyMatchesBruteForceOnRandomLabelings) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int n_truth = 2 + trial % 3, n_pred = 1 + trial % 5;
    std::uniform_int_distribution<int> t(0, n_truth - 1), p(-1, n_pred - 1);
    std::vector<int> truth(25), predicted(25);
    for (size_t k = 0; k < truth.size(); ++k) {
      truth[k] = t(rng);
      predicted[k] = p(rng);
    }
    EXPECT_NEAR(ClusteringAccuracy(truth, predicted),
                BruteForceAccuracy(truth, predicted, n_truth, n_pred), 1e-12);
  }
}

TEST(ClusteringMetrics, EmptyInputIsUndefined) {
  EXPECT_TRUE(std::isnan(ClusteringAccuracy({}, {})));
  EXPECT_TRUE(std::isnan(VariationOfInformation({}, {})));
}

}  // namespace
}  // namespace cslam
