#pragma once
// Walks two frame-ordered trajectories once, visiting the frames both have a pose at.
#include <map>

#include "core/rigid.h"

namespace cslam {

/// Calls visit(frame, a_pose, b_pose) for each frame in both `a` and `b`, ascending. The walk
/// starts where both have begun, so a long trajectory compared with a young one costs the
/// overlap, not the long one's history.
template <typename Visit>
void ForEachSharedFrame(const std::map<int, Pose>& a, const std::map<int, Pose>& b, Visit&& visit) {
  if (a.empty() || b.empty()) return;
  for (auto i = a.lower_bound(b.begin()->first), j = b.lower_bound(a.begin()->first);
       i != a.end() && j != b.end();) {
    if (i->first < j->first) {
      ++i;
    } else if (j->first < i->first) {
      ++j;
    } else {
      visit(i->first, i->second, j->second);
      ++i;
      ++j;
    }
  }
}

}  // namespace cslam
