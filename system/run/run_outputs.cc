#include "system/run/run_outputs.h"

#include <algorithm>

namespace cslam {

int PlacingPoseIndex(const Trajectory& cluster, int last_frame) {
  if (cluster.empty()) return -1;
  const auto it = std::lower_bound(cluster.frames.begin(), cluster.frames.end(), last_frame);
  if (it != cluster.frames.end() && *it == last_frame)
    return static_cast<int>(it - cluster.frames.begin());
  return static_cast<int>(cluster.size()) - 1;
}

}  // namespace cslam
