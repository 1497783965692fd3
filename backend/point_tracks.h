#pragma once
// Per-(landmark, frame) 3-D points with covariance: the input of the motion distance
// (clusterslam_spec.md §3). The first iteration of Algorithm 1 feeds camera-frame
// back-projections; later iterations feed positions refined by the previous MotionEstimate.
//
// Frame convention (both builders): every point is expressed in the CAMERA frame of its own
// frame t. Two landmarks observed at t are then in the same coordinate system, so the scalar
// distance ‖Xⁱₜ − Xʲₜ‖ stays a rigid-motion test whatever clusters they were assigned to.
// (Cluster-frame coordinates would not be: in its own cluster frame every landmark is static,
// so two different bodies would look rigidly attached to each other.)
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/motion_estimation.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"

namespace cslam {

/// One landmark's position at one frame: camera frame of `frame`, metres; covariance m².
struct PointSample {
  int frame = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  double disparity_px = 0.0;  ///< uL − uR of the observation (0: unknown)
  double metres_per_px = 0.0; ///< depth / focal length: lateral metres per pixel (0: unknown)
  bool clipped = false;       ///< StereoObservation::clipped: no evidence of motion
};

/// The samples of one landmark, ascending frame (a subset of its table observations).
struct PointTrack {
  std::vector<PointSample> samples;
};

/// Indexed by landmark id (size = table.num_landmarks()); empty tracks are allowed.
using PointTracks = std::vector<PointTrack>;

/// One observation back-projected: f(x), J_f Σ J_fᵀ, its disparity and metres per pixel;
/// nullopt when the disparity is not positive.
std::optional<PointSample> BackProjectObservation(const StereoObservation& o,
                                                  const StereoCamera& camera);

/// First iteration: f(xᵢₜ) and J_f Σᵢₜ J_fᵀ for every observation in `range` with positive
/// disparity.
PointTracks BackProjectTracks(const TrackletTable& table, const StereoCamera& camera,
                              FrameRange range);

/// Later iterations [ours]: per observation, the model prediction Pₜ = T^{cq}ₜ X̂^{q,i} (for the
/// static cluster T^{cq}ₜ = (P^c_t)⁻¹) plus the observation residual rₜ = f(xᵢₜ) − Pₜ averaged
/// over the landmark's own observations within ±`half_window` frames; covariance = the mean
/// back-projection covariance over those observations divided by their number. The average
/// removes noise (σ² / n) while a landmark that does not move with its cluster keeps a
/// residual drift, so a wrong assignment stays visible to the next clustering. `half_window`
/// = 0 reproduces BackProjectTracks. Observations without an estimate (label -1, a frame where
/// the cluster has no pose) fall back to the plain back-projection.
PointTracks RefineTracks(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                         const MotionEstimate& estimate, int half_window);

}  // namespace cslam
