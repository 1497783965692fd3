#pragma once
// A floor on the keypoint pixel covariances the backend is given [ours]. Why: every test of
// the backend is a χ² in these covariances — the motion distance (Eq. 1, 2), the noise-aware
// registration (Eq. 3), the bundle adjustment's whitened residuals (Eq. 5) and the model
// assignment's reduced χ². The synthetic generator at 0 px noise writes 1e-12 px²: the
// measurements are exact, but the estimates they are tested against are not (solver
// tolerances, the shape initialisation's drift), so every reduced χ² is ~1e10, every
// landmark fails every model, and the run ends with no cluster (measured on generated indoor
// and outdoor sequences, docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md).
// A covariance says how far the backend may
// trust a keypoint; no keypoint detector localises better than a fraction of a pixel.
// The floor scales a covariance whose largest axis is below it (FloorPixelCovariance).
#include <Eigen/Core>
#include <optional>

#include "core/tracklet_table.h"

namespace cslam {

/// `cov` scaled up so that its largest eigenvalue is at least min_sigma_px² (its shape kept);
/// unchanged when it already is. The floor is on the keypoint's claimed precision as a whole:
/// raising only the small eigenvalues would reshape the frontend's covariances, whose
/// disparity direction is legitimately thin (measured on KITTI raw 0005: an eigenvalue floor
/// made the camera clearly worse;
/// docs/experiments/2026-11-23-baselines-divergence-and-0px-noise.md).
Eigen::Matrix3d FloorPixelCovariance(const Eigen::Matrix3d& cov, double min_sigma_px);

/// The observations of `table` in `range` (same landmark ids, same num_landmarks) with every
/// covariance floored; nullopt — no copy — when no covariance in the range is below the floor
/// (ClusterSlamOptions::min_pixel_sigma says when the frontend's are).
std::optional<TrackletTable> FloorPixelCovariances(const TrackletTable& table, FrameRange range,
                                                   double min_sigma_px);

}  // namespace cslam
