#include "system/eval/object_camera_frame_error.h"

#include <cmath>

namespace cslam {

ObjectCameraFrameError ObjectErrorInCameraFrame(const std::vector<ObjectInCamera>& frames,
                                                bool fit_point) {
  ObjectCameraFrameError out;
  out.frames = static_cast<int>(frames.size());
  if (frames.size() < 3) return out;
  // p̂_k = R_k o + t_k + e_k; least squares in o: Σ R_kᵀ R_k = n I, so o is the mean of the
  // residuals carried into the object frame.
  if (fit_point) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const ObjectInCamera& f : frames)
      sum += f.gt_cam_from_object.linear().transpose() *
             (f.est_point_in_cam - f.gt_cam_from_object.translation());
    out.point_in_object = sum / static_cast<double>(frames.size());
  }
  double se = 0;
  for (const ObjectInCamera& f : frames)
    se += (f.est_point_in_cam - f.gt_cam_from_object * out.point_in_object).squaredNorm();
  out.rmse_m = std::sqrt(se / static_cast<double>(frames.size()));
  return out;
}

}  // namespace cslam
