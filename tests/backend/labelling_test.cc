#include "backend/labelling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cslam {
namespace {

TEST(Labelling, LabellingVariationIsZeroExactlyUpToRelabelling) {
  EXPECT_EQ(LabellingVariation({0, 0, 1, 1, 2}, {5, 5, 3, 3, 0}), 0.0);
  EXPECT_GT(LabellingVariation({0, 0, 1, 1, 2}, {5, 5, 3, 0, 0}), 0.1);
}

TEST(Labelling, LabellingVariationKnownValue) {
  // Two halves vs one cluster: VI = H(A) = log 2.
  EXPECT_NEAR(LabellingVariation({0, 0, 1, 1}, {0, 0, 0, 0}), std::log(2.0), 1e-12);
  // -1 is one more class over the entries where either labelling has a cluster.
  EXPECT_NEAR(LabellingVariation({0, 0, -1, -1, -1}, {0, 0, 0, 0, -1}), std::log(2.0), 1e-12);
}

TEST(Labelling, StaticIsTheClusterWithMostObservations) {
  // Cluster 7 has 3 landmarks × 2 observations; cluster 2 has 2 × 10.
  const std::vector<int> labels{7, 7, 7, 2, 2, -1, 4};
  const std::vector<int> obs{2, 2, 2, 10, 10, 50, 1};
  EXPECT_EQ(StaticFirstLabels(labels, obs), (std::vector<int>{1, 1, 1, 0, 0, -1, 2}));
}

TEST(Labelling, LaterStaticOverlapsMostWithThePreviousStatic) {
  const std::vector<int> labels{7, 7, 7, 2, 2, 4};
  const std::vector<int> obs{2, 2, 2, 10, 10, 1};
  const std::vector<int> previous{0, 0, 1, 1, 2, 0};  // landmarks 0, 1, 5 were static
  EXPECT_EQ(StaticFirstLabels(labels, obs, &previous), (std::vector<int>{0, 0, 0, 1, 1, 2}));
}

}  // namespace
}  // namespace cslam
