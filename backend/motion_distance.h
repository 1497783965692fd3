#pragma once
// Motion distance matrix of one chunk (clusterslam_spec.md §3, Eq. 1 and 2): how
// inconsistent the motions of two landmarks are. Sparse: only pairs co-observed at least
// `min_co_observations` times inside the chunk get an entry; the others are invalid.
#include <vector>

#include "backend/point_tracks.h"
#include "core/options_reader.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Parameters of Eq. 1.
struct MotionDistanceOptions {
  double alpha = 4e-4;            ///< weight of the image prior (dimensionless) [paper]
  int min_co_observations = 4;    ///< fewer co-observed frames → dᵢⱼ invalid [paper]
  bool use_uncertainty = true;    ///< false = ablation "w/o U": Euclidean first term, plain mean
  bool use_image_prior = true;    ///< false = ablation "w/o I"
  bool mean_over_frames = true;   ///< [ours] first term averaged over frames (false: summed)
  double min_variance_m2 = 1e-6;  ///< [ours] floor on σᵢⱼₜ, m², keeps log σ finite (also the
                                  ///< σ of two coincident points, where Eq. 2 is undefined)
  double max_extent_m = 0.0;      ///< [ours] 0 = off. Else adds (max(0, l* − R))² Σₜ 1/σᵢⱼₜ:
                                  ///< the χ² of the pair's mean distance l* lying beyond R m,
                                  ///< for groups known to be small bodies (re-clustered movers)
  void Check() const;
  void Load(OptionsReader& reader);
};

/// One valid entry of the symmetric matrix, a < b local indices.
struct DistanceEntry {
  int a = 0;
  int b = 0;
  double d = 0.0;
};

/// Sparse symmetric distance matrix over `landmarks.size()` items (local index → landmark id).
struct SparseDistances {
  std::vector<int> landmarks;
  std::vector<DistanceEntry> entries;
  int size() const { return static_cast<int>(landmarks.size()); }
};

/// Eq. 1 for every co-observed pair of the chunk. Items are the landmarks with at least
/// `min_co_observations` samples in `chunk` (ascending id). 3-D points and covariances come
/// from `tracks` (all in the camera frame of their frame, see point_tracks.h); the image prior
/// uses the stereo keypoints (uL, vL, uR) and pixel covariances of `table`. Only the chunk's
/// landmarks are touched (table.LandmarksIn), and pairs are found by a sweep over their frame
/// spans, so the cost follows the co-observed (pair, frame) count, never n² over all
/// landmarks of the sequence. Computed in float with double accumulators (~1e-6 relative).
SparseDistances ComputeMotionDistances(const TrackletTable& table, const PointTracks& tracks,
                                       FrameRange chunk, const MotionDistanceOptions& options);

}  // namespace cslam
