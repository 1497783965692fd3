#pragma once
// One fixed palette for every picture and point cloud, so a cluster keeps its colour across
// the trajectory plot, the snapshots, the overlays and landmarks.ply.
//
// Cluster ids: 0 is the static background, >= 1 are moving rigid bodies, -1 is "not yet
// clustered". Colours are RGB unless the name says BGR (OpenCV images are BGR).
#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace cslam {

/// RGB colour of `cluster`: static (0) grey, unclustered (< 0) light grey, moving clusters
/// (>= 1) cycle through a palette of distinct saturated colours readable on white.
cv::Vec3b ColorForCluster(int cluster);

/// ColorForCluster in OpenCV's BGR channel order (for drawing into and testing cv::Mat images).
cv::Vec3b BgrForCluster(int cluster);

/// ColorForCluster scaled to [0, 1] (for OpenGL).
Eigen::Vector3f ColorForClusterUnit(int cluster);

/// Cluster id of a legend-only trajectory line that stands for clusters not drawn (grey).
constexpr int kUndrawnClusters = -2;

/// Cluster id of a path drawn faint, for context only (the camera in render/objects.png).
constexpr int kContextPath = -3;

/// RGB line colour of a trajectory: the camera (cluster -1) is black, kUndrawnClusters grey,
/// kContextPath light grey, a cluster's trajectory uses ColorForCluster.
cv::Vec3b TrajectoryColor(int cluster);

/// Number of distinct colours before the moving-cluster palette repeats.
int ClusterPaletteSize();

}  // namespace cslam
