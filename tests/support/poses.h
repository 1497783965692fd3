#pragma once
// Poses that tests build by hand.
#include "core/rigid.h"

namespace cslam::testing {

/// A pure translation by (x, y, z) metres.
inline Pose Translation(double x, double y, double z) {
  Pose p = Pose::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

}  // namespace cslam::testing
