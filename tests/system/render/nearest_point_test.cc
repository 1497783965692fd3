#include "system/render/nearest_point.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cslam {
namespace {

// Brute force is the reference: the nearest point within the radius, or none.
TEST(NearestPointWithin, AgreesWithBruteForceInsideTheRadiusAndFindsNothingBeyondIt) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-10.f, 10.f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 300; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  points.emplace_back(NAN, 0.f, 0.f);
  const double radius = 1.5;
  const NearestPointWithin nearest(points, radius);
  int found = 0, none = 0;
  for (int q = 0; q < 3000; ++q) {
    const Eigen::Vector3f query(u(rng), u(rng), u(rng));
    int expected = -1;
    double best = radius * radius;
    for (int i = 0; i < static_cast<int>(points.size()); ++i) {
      if (!points[i].allFinite()) continue;
      const double sq = (points[i] - query).cast<double>().squaredNorm();
      if (sq <= best && (expected < 0 || sq < best)) best = sq, expected = i;
    }
    ASSERT_EQ(nearest.Find(query), expected) << q;
    (expected >= 0 ? found : none) += 1;
  }
  EXPECT_GT(found, 100);  // both outcomes are exercised
  EXPECT_GT(none, 100);
  EXPECT_EQ(NearestPointWithin({}, 1.0).Find({0, 0, 0}), -1);
}

}  // namespace
}  // namespace cslam
