#pragma once
// Random draws for test scenes that do not depend on the compiler. The order in which function
// arguments are evaluated is unspecified: `Vector3d(d(rng), d(rng), d(rng))` gives another
// vector under clang than under gcc, and so another scene (found when the suite first ran
// under clang's sanitizers). Draw3 fixes the order to z, y, x — gcc's, which the scenes'
// thresholds were set with.
#include <Eigen/Core>

namespace cslam::testing {

template <typename Draw>
Eigen::Vector3d Draw3(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return {x, y, z};
}

}  // namespace cslam::testing
