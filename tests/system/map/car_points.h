#pragma once
// A rigid body for the map's tests: points filling a car-sized box about its body origin.
#include <random>
#include <vector>

#include <Eigen/Core>

namespace cslam::testing {

/// 40 points in a 1.8 × 1.5 × 4 m box (x across, y down, z along) about the origin.
inline std::vector<Eigen::Vector3d> CarPoints(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 40; ++i) p.emplace_back(0.9 * u(rng), 0.75 * u(rng), 2.0 * u(rng));
  return p;
}

}  // namespace cslam::testing
