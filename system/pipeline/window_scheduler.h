#pragma once
// When the online system runs a backend window: every window_every frames over the last
// window_frames, never across a tracking break, and once more at the end.
#include <algorithm>
#include <optional>
#include <vector>

#include "core/tracklet_table.h"
#include "system/pipeline/pipeline_options.h"

namespace cslam {

/// Landmarks observed in both `frame` - 1 and `frame` (complete once `frame` is tracked).
int SharedWithPrevious(const TrackletTable& table, int frame);

/// Decides, frame by frame, which backend windows are due: the last window_frames frames every
/// window_every frames, and a last one at the end so every frame gets a pose. No window spans a
/// tracking break (consecutive frames sharing fewer than min_shared_landmarks landmarks): the
/// two sides are unconnected and no solver can place one relative to the other. So a break
/// closes the stretch before it with a window of its own, and windows after it start at it.
class WindowScheduler {
 public:
  explicit WindowScheduler(const OnlineOptions& o) : o_(o) {}

  /// Windows to run once frame `f` is tracked into `table`, in order.
  std::vector<FrameRange> AfterFrame(const TrackletTable& table, int f);
  /// The window after the last frame, when frames since the last window have no pose yet.
  std::optional<FrameRange> Final(int frames_done);
  /// A window that was not run after all (real-time mode, backend behind).
  void Skipped(FrameRange w) { last_end_ = std::min(last_end_, w.begin); }

 private:
  std::optional<FrameRange> Clip(FrameRange r) const;

  const OnlineOptions& o_;
  int last_end_ = 0;        // end of the last window scheduled
  int segment_begin_ = 0;   // first frame after the last tracking break
  bool broken_before_ = false;  // the previous frame was a break too (e.g. a run of black frames)
};

/// [0, frames) split at every tracking break; stretches too short to solve are left out
/// unless there is only one.
std::vector<FrameRange> SegmentsBetweenBreaks(const TrackletTable& table, int frames,
                                              const OnlineOptions& o);

}  // namespace cslam
