#include "backend/covariance_floor.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace cslam {

namespace {

// Largest eigenvalue of a symmetric 3×3; the diagonal case (the generator's) without a solver.
double LargestEigenvalue(const Eigen::Matrix3d& cov) {
  if (cov(0, 1) == 0 && cov(0, 2) == 0 && cov(1, 2) == 0) return cov.diagonal().maxCoeff();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

// A symmetric matrix's largest eigenvalue is at least its largest diagonal entry, so most
// covariances pass without the eigen-solver (every frontend one: it ran for each observation
// of every online window).
bool BelowFloor(const Eigen::Matrix3d& cov, double var) {
  if (cov.diagonal().maxCoeff() >= var) return false;
  return !(LargestEigenvalue(cov) >= var);
}

}  // namespace

Eigen::Matrix3d FloorPixelCovariance(const Eigen::Matrix3d& cov, double min_sigma_px) {
  const double var = min_sigma_px * min_sigma_px;
  if (!(var > 0)) return cov;
  const double largest = LargestEigenvalue(cov);
  if (largest >= var) return cov;
  if (!(largest > 0) || !cov.allFinite()) return var * Eigen::Matrix3d::Identity();
  return cov * (var / largest);
}

std::optional<TrackletTable> FloorPixelCovariances(const TrackletTable& table, FrameRange range,
                                                   double min_sigma_px) {
  const double var = min_sigma_px * min_sigma_px;
  if (!(var > 0)) return std::nullopt;
  const int end = std::min(range.end, table.num_frames());
  bool any = false;
  for (int f = std::max(range.begin, 0); f < end && !any; ++f)
    for (const ObservationRef& ref : table.ObservationsAt(f))
      if (BelowFloor(table.Get(ref).cov, var)) {
        any = true;
        break;
      }
  if (!any) return std::nullopt;
  TrackletTable floored;
  for (int f = std::max(range.begin, 0); f < end; ++f)
    for (const ObservationRef& ref : table.ObservationsAt(f)) {
      const StereoObservation& o = table.Get(ref);
      floored.Add(o.landmark, o.frame, o.x, FloorPixelCovariance(o.cov, min_sigma_px));
    }
  while (floored.num_landmarks() < table.num_landmarks()) floored.NewLandmark();
  return floored;
}

}  // namespace cslam
