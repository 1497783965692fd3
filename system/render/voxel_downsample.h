#pragma once
// A dense stereo cloud thinned to one point per occupied voxel: the centroid of the points in
// it. Voxels are cubes of one leaf size on a grid anchored at the origin, so the result does
// not depend on the order of the input.
#include <Eigen/Core>
#include <vector>

namespace cslam {

/// The centroids of the occupied voxels of edge `leaf_m` (> 0), ordered by voxel (x, then y,
/// then z index, ascending). Non-finite points are skipped.
std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points, double leaf_m);

}  // namespace cslam
