#include "system/run/version.h"

namespace cslam {
std::string VersionString() { return "clusterslam " CSLAM_VERSION; }
}  // namespace cslam
