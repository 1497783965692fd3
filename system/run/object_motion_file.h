#pragma once
// objects/<id>_motion.csv: an object's velocity, speed and position uncertainty per frame of
// its smoothed track (system/map/object_tracks.h; docs/formats.md).
#include <string>

#include "system/map/object_tracks.h"

namespace cslam {

/// Writes `track` atomically to `path`: one line per frame, with a header.
void WriteObjectMotion(const ObjectTrack& track, const std::string& path);

/// The 1-σ position uncertainty of a state: the standard deviation along the covariance's
/// least certain direction (its largest eigenvalue's root), metres.
double PositionSigma(const TrackState& state);

}  // namespace cslam
