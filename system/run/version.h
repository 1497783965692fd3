#pragma once
#include <string>

namespace cslam {
/// "clusterslam X.Y.Z" — printed by `cslam --version` and saved in every run's metrics.
std::string VersionString();
}  // namespace cslam
