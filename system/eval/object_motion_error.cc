#include "system/eval/object_motion_error.h"

#include <algorithm>
#include <cmath>

namespace cslam {

namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// The motion from frame a to frame b in the camera frame at a: cam_a ← world ← object.
Pose MotionInCamera(const Pose& world_from_cam_a, const Pose& world_from_obj_a,
                    const Pose& world_from_obj_b) {
  return Pose(world_from_cam_a.inverse() * world_from_obj_b * world_from_obj_a.inverse() *
              world_from_cam_a);
}

}  // namespace

ObjectMotionError ComputeObjectMotionError(const std::vector<ObjectFramePoses>& frames) {
  ObjectMotionError e;
  double sum_r = 0, sum_t = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const ObjectFramePoses& a = frames[k - 1];
    const ObjectFramePoses& b = frames[k];
    if (b.frame != a.frame + 1) continue;
    const Pose h_est = MotionInCamera(a.est_world_from_cam, a.est_world_from_object,
                                      b.est_world_from_object);
    const Pose h_gt = MotionInCamera(a.gt_world_from_cam, a.gt_world_from_object,
                                     b.gt_world_from_object);
    // The object's true centre at a, in the camera frame at a.
    const Eigen::Vector3d centre =
        a.gt_world_from_cam.inverse() * a.gt_world_from_object.translation();
    const double r = RotationAngle(h_gt.linear().transpose() * h_est.linear()) * kDegPerRad;
    const double t = (h_est * centre - h_gt * centre).norm();
    sum_r += r;
    sum_t += t;
    e.max_r_deg = std::max(e.max_r_deg, r);
    ++e.pairs;
  }
  if (e.pairs > 0) {
    e.me_r_deg = sum_r / e.pairs;
    e.me_t_m = sum_t / e.pairs;
  }
  return e;
}

std::optional<FrameToFrameRotation> LargestFrameToFrameRotation(
    const std::vector<int>& frames, const std::vector<Pose>& world_from_object) {
  std::optional<FrameToFrameRotation> largest;
  for (size_t k = 1; k < frames.size() && k < world_from_object.size(); ++k) {
    if (frames[k] != frames[k - 1] + 1) continue;
    const double r = RotationAngle(world_from_object[k - 1].linear().transpose() *
                                   world_from_object[k].linear()) *
                     kDegPerRad;
    if (!largest || r > largest->deg) largest = FrameToFrameRotation{r, frames[k]};
  }
  return largest;
}

}  // namespace cslam
