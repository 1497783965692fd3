#pragma once
// Splitting a moving cluster by place [ours, beyond the paper]. ClusterSLAM tells bodies apart
// by motion alone, and cars one behind the other at the same speed are one rigid motion to
// within the depth noise at 30–50 m (outdoor seed 1: three cars of one lane in one cluster;
// docs/experiments/2026-12-07-far-cars-labelled-static-online.md). Their landmarks, though, lie
// in groups metres apart with nothing between, which one vehicle's body does not have.
#include <vector>

#include <Eigen/Core>

#include "backend/motion_estimation.h"

namespace cslam {

/// The groups of `points` that single linkage at `gap_m` makes (points closer than gap_m are in
/// one group, transitively): for each point its group index, groups numbered by decreasing size.
std::vector<int> GroupsByGap(const std::vector<Eigen::Vector3d>& points, double gap_m);

/// Whether no point of `a` is within `gap_m` of a point of `b` (both in one frame).
bool SeparatedByGap(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                    double gap_m);

/// Splits each moving cluster of `estimate` whose landmarks (in the cluster's frame) form groups
/// more than `gap_m` apart: every group but the largest with at least `min_landmarks` becomes a
/// new cluster with a copy of the motion; the largest and the smaller groups keep the label.
/// Returns the clusters added.
int SplitClustersByPlace(double gap_m, int min_landmarks, MotionEstimate* estimate);

}  // namespace cslam
