#pragma once
// render/snapshot_NNNNNN.png and render/overlay_NNNNNN.png during a run: once a backend window
// settles the frames up to its end, the due frames' pictures are prepared from the map (plain
// data, so the map may change afterwards) and drawn and written on a writer thread, behind a
// bounded queue so a slow disk or renderer holds the backend back instead of filling memory.
#include <atomic>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/tracklet_table.h"
#include "system/map/map_state.h"
#include "system/pipeline/pipeline_options.h"
#include "system/pipeline/run_input.h"
#include "system/pipeline/frame_painter.h"
#include "system/runtime/bounded_queue.h"
#include "system/runtime/core_reservation.h"

namespace cslam {

/// Counts of what FrameRenders wrote.
struct FrameRenderStats {
  int snapshots = 0;
  int overlays = 0;
  int failed = 0;  ///< pictures not written (offscreen rendering unavailable, a write error)
};

/// Renders the per-frame pictures of OutputOptions into `out_dir`/render; see the file comment.
class FrameRenders {
 public:
  /// `painter` (may be null: nothing is drawn) draws each due frame. `threaded`: on a writer
  /// thread, its nice value raised by `writer_nice` (see OnlineOptions::background_nice) and a
  /// background thread of `reservation` when given; otherwise inline, in order (sequential
  /// runs).
  FrameRenders(const RunInput& input, const OutputOptions& options, std::string out_dir,
               std::shared_ptr<const FramePainter> painter, bool threaded, int writer_nice = 0,
               CoreReservation* reservation = nullptr);
  ~FrameRenders();
  FrameRenders(const FrameRenders&) = delete;
  FrameRenders& operator=(const FrameRenders&) = delete;

  /// Whether any per-frame picture is asked for.
  bool enabled() const { return snapshots_every_ > 0 || overlays_every_ > 0; }
  /// After `map` integrated a window over `range` with observations `window_table`: renders
  /// every due frame before range.end that was not rendered yet, showing the moving clusters
  /// in `reported` (system/map/object_report.h) as objects and the others' points as outliers.
  /// `ids` (may be null): the map's landmark id of each of `window_table`'s.
  void AfterWindow(const MapState& map, const std::set<int>& reported,
                   const TrackletTable& window_table, FrameRange range,
                   const std::vector<int>* ids = nullptr);
  /// Waits for the writer to finish everything queued; returns what was written.
  FrameRenderStats Finish();

  /// Frames of the trajectories drawn behind the camera in a snapshot.
  static constexpr int kRecentFrames = 60;
  /// Frames of each keypoint's trail on an overlay.
  static constexpr int kTrailFrames = 6;

 private:
  void Draw(const FrameScene& scene);

  const RunInput& input_;
  std::shared_ptr<const FramePainter> painter_;
  int snapshots_every_ = 0, overlays_every_ = 0;
  bool dense_ = false;
  std::string render_dir_;
  int next_frame_ = 0;  ///< frames before this are done
  FrameRenderStats stats_;
  std::unique_ptr<BoundedQueue<FrameScene>> queue_;
  std::thread writer_;
};

}  // namespace cslam
