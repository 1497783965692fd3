#include "system/render/nearest_point.h"

#include <cmath>
#include <limits>

#include "core/errors.h"

namespace cslam {

size_t NearestPointWithin::CellHash::operator()(const std::array<long long, 3>& c) const {
  size_t h = 1469598103934665603ull;
  for (long long v : c) h = (h ^ static_cast<size_t>(v)) * 1099511628211ull;
  return h;
}

std::array<long long, 3> NearestPointWithin::CellOf(const Eigen::Vector3f& p) const {
  return {static_cast<long long>(std::floor(p.x() / radius_m_)),
          static_cast<long long>(std::floor(p.y() / radius_m_)),
          static_cast<long long>(std::floor(p.z() / radius_m_))};
}

NearestPointWithin::NearestPointWithin(std::vector<Eigen::Vector3f> points, double radius_m)
    : points_(std::move(points)), radius_m_(radius_m) {
  CSLAM_CHECK(radius_m > 0, "search radius must be > 0");
  for (int i = 0; i < static_cast<int>(points_.size()); ++i)
    if (points_[static_cast<size_t>(i)].allFinite()) cells_[CellOf(points_[static_cast<size_t>(i)])].push_back(i);
}

int NearestPointWithin::Find(const Eigen::Vector3f& q) const {
  if (!q.allFinite()) return -1;
  const std::array<long long, 3> c = CellOf(q);
  int best = -1;
  double best_sq = radius_m_ * radius_m_;
  for (long long dx = -1; dx <= 1; ++dx)
    for (long long dy = -1; dy <= 1; ++dy)
      for (long long dz = -1; dz <= 1; ++dz) {
        const auto it = cells_.find({c[0] + dx, c[1] + dy, c[2] + dz});
        if (it == cells_.end()) continue;
        for (int i : it->second) {
          const double sq = (points_[static_cast<size_t>(i)] - q).cast<double>().squaredNorm();
          if (sq < best_sq || (sq == best_sq && (best < 0 || i < best))) {
            best_sq = sq;
            best = i;
          }
        }
      }
  return best;
}

}  // namespace cslam
