#pragma once
// At the end of a run, each reported object gets a body frame of its own and a track a body
// could drive. The map's cluster frame is the camera frame where the cluster was first seen,
// often 40 m from the object, so a heading error of a few degrees moved the object by metres
// and a flipped heading by tens of metres. The body frame is fixed to the object with its
// origin at its landmarks' centroid and its axes the world's at its first frame; each frame's
// pose from the windows becomes a measurement whose covariance its visible landmarks' stereo
// uncertainty gives (system/map/track_smoother.h), and the smoothed track replaces the poses,
// including frames of gaps up to the smoother's max_gap_s. Where the body's own kept
// keypoints (MapState::object_observations) refuse the windows' places of it, they place it
// instead (system/map/observed_position.h; docs/backend.md map step 6).
#include <map>
#include <vector>

#include "core/stereo_camera.h"
#include "core/task_runner.h"
#include "core/tracklet_table.h"
#include "system/map/map_state.h"
#include "system/map/object_track_options.h"
#include "system/map/track_smoother.h"

namespace cslam {

/// One object's smoothed track.
struct ObjectTrack {
  std::vector<TrackState> states;  ///< ascending frames
  int measurements = 0;            ///< frames whose pose the windows gave
  int rejected_positions = 0, rejected_rotations = 0;
  int adjusted_frames = 0;  ///< poses the object adjustment refitted to the keypoints
};

/// Re-frames every moving cluster of `map` to its body frame and, with options.smooth,
/// replaces its trajectory by the smoothed one. `timestamps` gives each frame's time (frames
/// past its end: map frame_period_s apart). Returns the tracks by cluster id (empty without
/// smoothing). The objects' adjustments run through `runner` (one after another without it).
std::map<int, ObjectTrack> MakeObjectTracks(MapState* map, const TrackletTable& table,
                                            const StereoCamera& camera,
                                            const std::vector<double>& timestamps,
                                            double frame_period_s,
                                            const ObjectTrackOptions& options,
                                            const TaskRunner* runner = nullptr);

}  // namespace cslam
