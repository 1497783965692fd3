#pragma once
// Are the frontend's keypoint covariances honest on this sequence? The moving-or-static test
// (backend/moving_test.h) is only as good as they are. The static landmarks' observations are
// whitened under the run's final camera poses: each landmark is placed where its observations
// agree best (Gauss–Newton on the whitened stereo reprojection error), observations whose
// χ²(3) exceeds the gate are cut as outliers (the heavy tail of tracks that follow no physical
// point), and the rest should follow χ² with 3 n − 3 degrees of freedom per landmark: a mean
// per degree of freedom near 1 says the covariances are right, below 1 pessimistic, above 1
// optimistic.
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "system/map/map_state.h"

namespace cslam {

/// The static landmarks' whitened residuals (see the file comment).
struct NoiseCheck {
  int landmarks = 0;              ///< static landmarks with >= 3 observations kept
  long long observations = 0;     ///< their observations, before the cut
  double chi2_per_dof = 0.0;      ///< Σ χ² / Σ (3 n − 3) over the kept observations
  double cut_fraction = 0.0;      ///< observations cut by the gate / observations
};

/// `disparity_offset_px` is the offset the run applied to every disparity (0: none).
/// `gate_chi2`: χ²(3) 0.999 by default.
NoiseCheck CheckStaticNoise(const MapState& map, const TrackletTable& table,
                            const StereoCamera& camera, double disparity_offset_px = 0.0,
                            double gate_chi2 = 16.27);

}  // namespace cslam
