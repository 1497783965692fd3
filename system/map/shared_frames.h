#pragma once
// Walks two frame-ordered trajectories once, visiting the frames both have a pose at.
#include <map>

#include "core/rigid.h"

namespace cslam {

/// Calls visit(frame, a_pose, b_pose) for each frame in both `a` and `b`, ascending.
template <typename Visit>
void ForEachSharedFrame(const std::map<int, Pose>& a, const std::map<int, Pose>& b, Visit&& visit) {
  for (auto i = a.begin(), j = b.begin(); i != a.end() && j != b.end();) {
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
