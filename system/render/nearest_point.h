#pragma once
// Which of a set of points is nearest to a query, within a search radius: a uniform grid of
// cells one radius wide, so a query looks at its own cell and the 26 around it.
#include <Eigen/Core>
#include <array>
#include <unordered_map>
#include <vector>

namespace cslam {

/// Nearest-point queries over fixed points, bounded by a radius.
class NearestPointWithin {
 public:
  /// `points` may hold non-finite entries (never returned); `radius_m` > 0.
  NearestPointWithin(std::vector<Eigen::Vector3f> points, double radius_m);
  /// Index of the nearest point at most the radius from `q` (the lowest index among equally
  /// near ones), -1 when there is none.
  int Find(const Eigen::Vector3f& q) const;

 private:
  struct CellHash {
    size_t operator()(const std::array<long long, 3>& c) const;
  };
  std::array<long long, 3> CellOf(const Eigen::Vector3f& p) const;
  std::vector<Eigen::Vector3f> points_;
  double radius_m_;
  std::unordered_map<std::array<long long, 3>, std::vector<int>, CellHash> cells_;
};

}  // namespace cslam
