#include "system/map/co_location.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "system/map/shared_frames.h"

namespace cslam {

namespace {

struct Extent {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;  // RMS distance of the points from the centre
};

// A cluster is one rigid shape in its own frame: its extent is measured there once and only
// its centre moves.
Extent ExtentOf(const std::vector<Eigen::Vector3d>& points) {
  Extent e;
  for (const auto& p : points) e.centre += p;
  e.centre /= static_cast<double>(points.size());
  double s = 0;
  for (const auto& p : points) s += (p - e.centre).squaredNorm();
  e.radius = std::sqrt(s / static_cast<double>(points.size()));
  return e;
}

}  // namespace

CoLocation CompareLocations(const std::map<int, Pose>& world_from_a,
                            const std::vector<Eigen::Vector3d>& points_in_a,
                            const std::map<int, Pose>& world_from_b,
                            const std::vector<Eigen::Vector3d>& points_in_b) {
  CoLocation result;
  if (points_in_a.empty() || points_in_b.empty()) return result;
  const Extent ea = ExtentOf(points_in_a), eb = ExtentOf(points_in_b);
  const double radius = std::min(ea.radius, eb.radius);
  std::vector<double> ratios;
  ForEachSharedFrame(world_from_a, world_from_b, [&](int, const Pose& a, const Pose& b) {
    const double d = (a * ea.centre - b * eb.centre).norm();
    ratios.push_back(radius > 0 ? d / radius
                                : (d > 0 ? std::numeric_limits<double>::infinity() : 0.0));
  });
  result.frames = static_cast<int>(ratios.size());
  if (ratios.empty()) return result;
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  result.median_ratio = ratios[ratios.size() / 2];
  return result;
}

}  // namespace cslam
