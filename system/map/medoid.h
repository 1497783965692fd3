#pragma once
// The medoid of a set: the member nearest, in summed distance, to all the others. The windows'
// estimates of an object are fused by it (system/map/object_tracks.h, track_smoother.h), since
// one estimate that flipped the body moves a mean but not a medoid.
#include <cmath>
#include <cstddef>

namespace cslam {

/// The index in [first, last) whose summed `distance(i, j)` over j in [first, last) is least
/// (the first such on ties); `first` when the range is empty.
template <typename Distance>
size_t MedoidIndex(size_t first, size_t last, Distance&& distance) {
  size_t best = first;
  double min_sum = INFINITY;
  for (size_t i = first; i < last; ++i) {
    double sum = 0;
    for (size_t j = first; j < last; ++j) sum += distance(i, j);
    if (sum < min_sum) min_sum = sum, best = i;
  }
  return best;
}

}  // namespace cslam
