#pragma once
// landmarks.ply / landmarks.pcd: the landmarks in the world frame, each with the RGB colour of
// its cluster (ColorForCluster), readable by PCL, CloudCompare, MeshLab, Open3D.
#include <string>
#include <vector>

#include "system/draw/render_scene.h"

namespace cslam {

/// Writes `points` as binary PLY to `ply_path` and binary PCD to `pcd_path` (PCL's PointXYZRGB,
/// float coordinates), each through a temporary file renamed into place; missing folders are
/// created. Points with non-finite coordinates are skipped. Throws OutputError naming the file
/// on failure.
void WriteLandmarkClouds(const std::vector<RenderPoint>& points, const std::string& ply_path,
                         const std::string& pcd_path);

}  // namespace cslam
