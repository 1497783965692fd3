#pragma once
// The two ways of running the whole system over an input (docs/architecture.md):
//  - batch: the frontend over every frame, then one backend call over the whole sequence;
//  - online: reader → frontend → backend windows → map, each stage on its own thread with
//    bounded queues (or all in one thread, in order, with OnlineOptions::sequential).
// Both end in a MapState, so outputs, metrics and renders are written the same way.
#include <atomic>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "backend/backend_result.h"
#include "backend/window_prior.h"
#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "system/map/map_state.h"
#include "system/map/object_tracks.h"
#include "system/pipeline/frame_renders.h"
#include "system/pipeline/pipeline_options.h"
#include "system/runtime/resource_log.h"
#include "system/pipeline/run_input.h"

namespace cslam {

/// One backend window of the online system (or the single batch call).
struct WindowStats {
  FrameRange range;
  double backend_ms = 0.0;    ///< RunClusterSlam / baseline wall time, incl. building the prior
  double prior_ms = 0.0;      ///< of backend_ms: building the window's prior from the map
  double backend_cpu_ms = 0.0;  ///< CPU time of the backend thread over backend_ms
  double worker_cpu_ms = 0.0;   ///< ... and of the backend's worker threads (backend_threads > 1)
  bool warm_started = false;  ///< the backend started from the map's prior
  double integrate_ms = 0.0;  ///< association + stitching
  double integrate_cpu_ms = 0.0;  ///< CPU time of the backend thread over integrate_ms
  double render_ms = 0.0;     ///< preparing and queuing the due snapshots / overlays
  int clusters = 0;           ///< moving clusters found in the window
  int live_clusters = 0;      ///< the map's moving clusters with a live landmark afterwards
  int live_landmarks = 0;     ///< the map's live (not retired) landmarks afterwards
  bool failed = false;        ///< discarded (solver failure, non-finite poses, too few landmarks)
  bool adjustment_failed = false;  ///< its final bundle adjustment was not usable: integrated
                                   ///< with the estimate that adjustment was given
  WindowIntegration integration;
};

/// Everything a run produced.
struct PipelineResult {
  MapState map;
  TrackletTable table;
  std::vector<FrameSummary> frontend_frames;  ///< empty when tracklets were given
  std::vector<WindowStats> windows;
  std::optional<BackendResult> batch;         ///< the batch backend call (batch mode only)
  int frames_processed = 0;
  int windows_skipped = 0;   ///< real-time mode: windows dropped because the backend lagged
  bool interrupted = false;  ///< stopped by a stop request before the end of the input
  double total_s = 0.0;
  double read_ms_per_frame = 0.0;
  double read_cpu_ms_per_frame = 0.0;  ///< CPU time of the reading thread (image decoding)
  /// Resident memory and time every few frames (resources.csv, render/resources.png).
  std::vector<ResourceSample> resources;
  FrameRenderStats renders;  ///< snapshots and overlays written during the run
  /// The reported objects' smoothed tracks by cluster id (system/map/object_tracks.h): each
  /// frame's velocity and uncertainty; their poses are the map's.
  std::map<int, ObjectTrack> object_tracks;
  /// calibration.estimate_disparity_offset: what the self-calibration found and applied.
  std::optional<DisparityOffsetCalibration> disparity_offset;
  /// A failure part-way (e.g. a corrupt image): the run stopped there; everything above is
  /// what was estimated before it. The caller writes the outputs, then rethrows.
  std::exception_ptr error;
};

/// Called after each frame with (frames done, frames total, objects the map would report so
/// far); for progress bars. Batch runs report no objects until the end (0).
using ProgressCallback = std::function<void(int, int, int)>;

/// The backend call of one window (RunBackend unless a test injects a fault). The prior is
/// the map's for online ClusterSLAM windows (null for batch runs, the baselines, the first
/// window and windows after a tracking break).
using BackendFunction =
    std::function<BackendResult(const TrackletTable&, const StereoCamera&, FrameRange,
                                const PipelineOptions&, const WindowPrior*)>;

/// Runs the system over `input` in options.mode. `stop` (may be null) is polled; when it
/// becomes true the run winds down and returns what was estimated so far. A window whose
/// backend call throws (other than ConfigError) or returns no usable estimate is discarded
/// and logged (WindowStats::failed); the run goes on. No window spans a tracking break
/// (OnlineOptions::min_shared_landmarks). `backend` replaces RunBackend (tests only).
PipelineResult RunPipeline(const RunInput& input, const PipelineOptions& options,
                           const std::atomic<bool>* stop = nullptr,
                           const ProgressCallback& progress = {},
                           const BackendFunction& backend = {});

/// Throws ConfigError when `method` cannot run on `input`: "true-labels" needs the
/// generator's landmark objects, which only replayed synthetic tracklets carry.
void CheckMethodFitsInput(Method method, const RunInput& input);

/// The backend method named in options over `range` of `table` (no threads of its own).
/// ClusterSLAM starts from `prior` when it is usable (RunClusterSlamWindow); the baselines
/// ignore it.
BackendResult RunBackend(const TrackletTable& table, const StereoCamera& camera, FrameRange range,
                         const PipelineOptions& options, const WindowPrior* prior = nullptr);

}  // namespace cslam
