#pragma once
// Options of the end-of-run object tracks (system/map/object_tracks.h), YAML section
// `map.track`; the smoother's keys sit in the same section.
#include "core/options_reader.h"
#include "system/map/track_smoother.h"

namespace cslam {

/// Options of the end-of-run object tracks.
struct ObjectTrackOptions {
  /// false: the objects keep the windows' poses (in their body frames).
  bool smooth = true;
  /// The smoothed track and the landmarks' places are refitted to the kept keypoints under the
  /// smoother's motion model (system/map/object_adjustment.h).
  bool adjust = true;
  /// Standard deviation of a keypoint (px) in the landmarks' measurement covariance.
  double pixel_sigma = 1.0;
  TrackSmootherOptions smoother;
  void Check() const;
  void Load(OptionsReader& r);
};

}  // namespace cslam
