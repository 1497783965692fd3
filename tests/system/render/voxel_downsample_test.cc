#include "system/render/voxel_downsample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>

namespace cslam {
namespace {

// Independent computation: bucket by voxel in a std::map, average in double.
TEST(VoxelCentroids, EachOccupiedVoxelGivesTheMeanOfItsPointsInVoxelOrder) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.f, 3.f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 4000; ++i) points.emplace_back(u(rng), u(rng), 0.5f * u(rng));
  points.emplace_back(NAN, 0.f, 0.f);  // skipped
  const double leaf = 0.4;
  std::map<std::tuple<long, long, long>, std::pair<Eigen::Vector3d, int>> buckets;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    auto& b = buckets[{std::lround(std::floor(p.x() / leaf)), std::lround(std::floor(p.y() / leaf)),
                       std::lround(std::floor(p.z() / leaf))}];
    if (b.second == 0) b.first.setZero();  // Eigen leaves a default vector uninitialised
    b.first += p.cast<double>();
    ++b.second;
  }
  const std::vector<Eigen::Vector3f> got = VoxelCentroids(points, leaf);
  ASSERT_EQ(got.size(), buckets.size());
  size_t k = 0;
  for (const auto& [voxel, b] : buckets) {
    const Eigen::Vector3d expected = b.first / b.second;
    EXPECT_LT((got[k++].cast<double>() - expected).norm(), 1e-5);
  }
  // Every centroid lies inside its own voxel, so no two share one.
  EXPECT_LT(got.size(), points.size() / 2);
}

TEST(VoxelCentroids, PointsOnBothSidesOfTheOriginFallInSeparateVoxels) {
  const std::vector<Eigen::Vector3f> points = {{-0.01f, 0.f, 0.f}, {0.01f, 0.f, 0.f}};
  EXPECT_EQ(VoxelCentroids(points, 1.0).size(), 2u);
  EXPECT_TRUE(VoxelCentroids({}, 1.0).empty());
}

}  // namespace
}  // namespace cslam
