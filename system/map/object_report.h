#pragma once
// Which of the map's moving clusters are reported as objects (objects/, clusters.csv, the
// renders, metrics.json). The backend already dissolved, window by window, every cluster
// whose tracks the static world's motion explains (backend/moving_test.h); what reaches the
// map may still be a fragment of a few landmarks or a few frames, too little to tell a body
// from a coincidence. Those are not reported, and their landmarks are outliers (-1).
#include <set>

#include "system/map/map_state.h"

namespace cslam {

/// Ids of the moving clusters of `map` with at least options.report_min_landmarks landmarks,
/// poses at at least options.report_min_frames frames, found by at least
/// options.report_min_windows windows (or by every window covering its frames).
std::set<int> ReportedClusters(const MapState& map, const MapStateOptions& options);

/// The landmarks (live and retired) of the clusters ReportedClusters selects.
std::set<int> ReportedLandmarks(const MapState& map, const MapStateOptions& options);

/// Releases every moving cluster of `map` that holds none of `landmarks`
/// (MapState::ReleaseCluster; returns how many). With ReportedLandmarks taken before the
/// end-of-run merges: a fragment may join an object, but fragments that only joined each other
/// are still too little to tell a body from a coincidence.
int KeepClustersHolding(MapState* map, const std::set<int>& landmarks);

}  // namespace cslam

