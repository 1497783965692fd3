// TEMPORARY link-time stand-ins for backend/motion_estimation.cc, which the `slam` branch is
// writing. Delete this file when that branch is merged.
#include "backend/motion_estimation.h"
#include "tests/backend/fake_motion_estimator.h"

namespace cslam {

MotionEstimate EstimateMotions(const TrackletTable& table, const StereoCamera& camera,
                               FrameRange range, const std::vector<int>& landmark_cluster,
                               const MotionEstimationOptions& options) {
  return testing::FakeEstimateMotions(table, camera, range, landmark_cluster, options);
}

void MotionEstimationOptions::Check() const {}

void MotionEstimationOptions::Load(OptionsReader& reader) {
  reader.Read("point_to_point_icp", &point_to_point_icp);
}

const ClusterMotion* MotionEstimate::FindCluster(int label) const {
  for (const auto& c : clusters)
    if (c.cluster == label) return &c;
  return nullptr;
}

}  // namespace cslam
