#include "system/render/voxel_downsample.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/errors.h"

namespace cslam {

std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points, double leaf_m) {
  CSLAM_CHECK(leaf_m > 0, "voxel leaf size must be > 0");
  struct Entry {
    std::array<long long, 3> voxel;
    int index;
  };
  std::vector<Entry> entries;
  entries.reserve(points.size());
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector3f& p = points[static_cast<size_t>(i)];
    if (!p.allFinite()) continue;
    Entry e{};
    for (int a = 0; a < 3; ++a) e.voxel[static_cast<size_t>(a)] = static_cast<long long>(std::floor(p[a] / leaf_m));
    e.index = i;
    entries.push_back(e);
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.voxel != b.voxel ? a.voxel < b.voxel : a.index < b.index;
  });
  std::vector<Eigen::Vector3f> centroids;
  for (size_t begin = 0; begin < entries.size();) {
    size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < entries.size() && entries[end].voxel == entries[begin].voxel)
      sum += points[static_cast<size_t>(entries[end++].index)].cast<double>();
    centroids.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
  return centroids;
}

}  // namespace cslam
