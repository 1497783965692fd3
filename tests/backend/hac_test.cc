#include "backend/hac.h"

#include <gtest/gtest.h>

#include <utility>

#include <cmath>
#include <limits>
#include <random>

#include "backend/labelling.h"

namespace cslam {
namespace {

SparseDistances FromEntries(int n, std::vector<DistanceEntry> entries) {
  SparseDistances d;
  for (int i = 0; i < n; ++i) d.landmarks.push_back(i);
  d.entries = std::move(entries);
  return d;
}

HacOptions Eps(double e) {
  HacOptions o;
  o.epsilon = e;
  return o;
}

// Complete linkage by brute force: every step scans all cluster pairs and recomputes the
// linkage as the max over valid member pairs. O(n^4); the reference for small n.
std::vector<int> BruteForceHac(int n, const std::vector<DistanceEntry>& entries, double eps) {
  const double kNone = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<double>> d(n, std::vector<double>(n, kNone));
  for (const auto& e : entries) d[e.a][e.b] = d[e.b][e.a] = e.d;
  std::vector<std::vector<int>> clusters(n);
  for (int i = 0; i < n; ++i) clusters[i] = {i};
  for (;;) {
    double best = std::numeric_limits<double>::infinity();
    int ba = -1, bb = -1;
    for (size_t a = 0; a < clusters.size(); ++a)
      for (size_t b = a + 1; b < clusters.size(); ++b) {
        double link = -std::numeric_limits<double>::infinity();
        bool defined = false;
        for (int i : clusters[a])
          for (int j : clusters[b])
            if (!std::isnan(d[i][j])) link = std::max(link, d[i][j]), defined = true;
        if (defined && link < best) best = link, ba = static_cast<int>(a), bb = static_cast<int>(b);
      }
    if (ba < 0 || best > eps) break;
    clusters[ba].insert(clusters[ba].end(), clusters[bb].begin(), clusters[bb].end());
    clusters.erase(clusters.begin() + bb);
  }
  std::vector<int> labels(n);
  for (size_t c = 0; c < clusters.size(); ++c)
    for (int i : clusters[c]) labels[i] = static_cast<int>(c);
  return labels;
}

TEST(Hac, TwoWellSeparatedGroups) {
  // {0,1,2} and {3,4}: within 5..10, across 100.
  std::vector<DistanceEntry> e;
  for (int i = 0; i < 5; ++i)
    for (int j = i + 1; j < 5; ++j) e.push_back({i, j, (i < 3) == (j < 3) ? 5.0 + i + j : 100.0});
  EXPECT_EQ(CompleteLinkageHac(FromEntries(5, e), Eps(60)), (std::vector<int>{0, 0, 0, 1, 1}));
}

TEST(Hac, NonTransitiveChainIsNotMergedIntoOneCluster) {
  // a~b, b~c, a≁c: single linkage would chain them; complete linkage must not.
  const auto labels =
      CompleteLinkageHac(FromEntries(3, {{0, 1, 10}, {1, 2, 11}, {0, 2, 100}}), Eps(60));
  EXPECT_EQ(labels, (std::vector<int>{0, 0, 1}));
}

TEST(Hac, PairsWithoutAnyValidEntryNeverMergeDirectly) {
  // 0-1 close, 2-3 close, no valid entry between the two groups: four items, two clusters.
  const auto labels = CompleteLinkageHac(FromEntries(4, {{0, 1, 1}, {2, 3, 2}}), Eps(60));
  EXPECT_EQ(labels, (std::vector<int>{0, 0, 1, 1}));
  // An isolated item stays alone.
  EXPECT_EQ(CompleteLinkageHac(FromEntries(3, {{0, 1, 1}}), Eps(60)),
            (std::vector<int>{0, 0, 1}));
}

TEST(Hac, LinkageIsTheMaximumOverTheValidMemberPairs) {
  // {0,1} merge first (d=1). 2 has a valid entry only with 1 (d=20): the linkage of {0,1}
  // and 2 is 20 (the invalid 0-2 is ignored), so 2 joins. 3 is close to 0 (5) but far from
  // 1 (70): linkage 70 > 60, stays alone.
  const auto labels = CompleteLinkageHac(
      FromEntries(4, {{0, 1, 1}, {1, 2, 20}, {0, 3, 5}, {1, 3, 70}}), Eps(60));
  EXPECT_EQ(labels, (std::vector<int>{0, 0, 0, 1}));
}

TEST(Hac, MergesAtExactlyEpsilonButNotAbove) {
  EXPECT_EQ(CompleteLinkageHac(FromEntries(2, {{0, 1, 60.0}}), Eps(60)), (std::vector<int>{0, 0}));
  EXPECT_EQ(CompleteLinkageHac(FromEntries(2, {{0, 1, 60.0001}}), Eps(60)),
            (std::vector<int>{0, 1}));
}

TEST(Hac, NegativeDistancesAreOrdinaryValues) {
  // Eq. 1 can be negative (log variances); -5 must still be the closest pair.
  EXPECT_EQ(CompleteLinkageHac(FromEntries(3, {{0, 1, 30}, {1, 2, -5}, {0, 2, 61}}), Eps(60)),
            (std::vector<int>{0, 1, 1}));
}

TEST(Hac, AgreesWithBruteForceOnRandomSparseMatrices) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 5 + trial % 25;
    // Planted groups: small within, large across, plus random holes (invalid entries).
    std::vector<int> group(n);
    for (int i = 0; i < n; ++i) group[i] = static_cast<int>(u(rng) * 4);
    const double hole = trial % 3 == 0 ? 0.0 : 0.3;
    std::vector<DistanceEntry> e;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        if (u(rng) < hole) continue;
        const double d = group[i] == group[j] ? 80 * u(rng) - 20 : 40 + 100 * u(rng);
        e.push_back({i, j, d});
      }
    const auto want = BruteForceHac(n, e, 60.0);
    for (int dense_limit : {0, 2048}) {  // the sparse and the dense engine
      HacOptions o = Eps(60);
      o.max_dense_items = dense_limit;
      const auto got = CompleteLinkageHac(FromEntries(n, e), o);
      EXPECT_EQ(got, want) << "trial " << trial << " dense limit " << dense_limit;
    }
  }
}

TEST(Hac, SparseEngineHandlesInvalidEntriesLikeTheDenseOne) {
  HacOptions o = Eps(60);
  o.max_dense_items = 0;
  EXPECT_EQ(CompleteLinkageHac(
                FromEntries(4, {{0, 1, 1}, {1, 2, 20}, {0, 3, 5}, {1, 3, 70}}), o),
            (std::vector<int>{0, 0, 0, 1}));
  EXPECT_EQ(CompleteLinkageHac(FromEntries(3, {{0, 1, 10}, {1, 2, 11}, {0, 2, 100}}), o),
            (std::vector<int>{0, 0, 1}));
}

TEST(Hac, GivenTheDistancesToKeepItFreesThemAndAgreesWithTheCopyingCall) {
  const SparseDistances d = FromEntries(4, {{0, 1, 1}, {1, 2, 20}, {0, 3, 5}, {1, 3, 70}});
  for (int dense_limit : {0, 2048}) {
    HacOptions o = Eps(60);
    o.max_dense_items = dense_limit;
    const std::vector<int> kept = CompleteLinkageHac(d, o);
    EXPECT_EQ(d.entries.size(), 4u);
    SparseDistances given = d;
    EXPECT_EQ(CompleteLinkageHac(std::move(given), o), kept);
    EXPECT_EQ(given.entries.capacity(), 0u);
    EXPECT_EQ(given.landmarks, d.landmarks);
  }
}

TEST(Hac, EmptyInputGivesNoLabels) {
  EXPECT_TRUE(CompleteLinkageHac(SparseDistances(), Eps(60)).empty());
}

}  // namespace
}  // namespace cslam
