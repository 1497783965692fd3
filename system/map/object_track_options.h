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
  /// With the tracks made, objects that occupy one place (the map's place test,
  /// map.co_location_ratio) are merged and their union tracked again: the windows judged that
  /// test on poses metres off for a far car, so a car handed from one window cluster to the
  /// next within a frame or two could stay two objects.
  bool merge_co_located = true;
  /// ... and each object that starts at most this long after another ended is joined to it
  /// when it lies where that body, carried on at constant velocity with at most
  /// join_max_acceleration_mps2, could have got to and no other body could have
  /// (system/map/reappearance.h, on the tracks' poses): a far car that the windows lost for a
  /// few frames and found again as a new cluster is one object. 0 = off.
  double join_max_gap_s = 0.5;
  double join_max_acceleration_mps2 = 3.0;
  /// Standard deviation of a keypoint (px) in the landmarks' measurement covariance.
  double pixel_sigma = 1.0;
  TrackSmootherOptions smoother;
  void Check() const;
  void Load(OptionsReader& r);
};

}  // namespace cslam
