#include "system/pipeline/window_scheduler.h"

#include <algorithm>

#include "core/logging.h"

namespace cslam {

namespace {
// A stretch after a tracking break needs this many frames to be worth a backend call.
constexpr int kMinClippedFrames = 3;
}  // namespace

int SharedWithPrevious(const TrackletTable& table, int frame) {
  if (frame <= 0 || frame >= table.num_frames()) return 0;
  int shared = 0;
  for (const ObservationRef& ref : table.ObservationsAt(frame))
    if (ref.index > 0 && table.Get({ref.landmark, ref.index - 1}).frame == frame - 1) ++shared;
  return shared;
}

std::vector<FrameRange> WindowScheduler::AfterFrame(const TrackletTable& table, int f) {
  std::vector<FrameRange> due;
  if (f > 0 && SharedWithPrevious(table, f) < o_.min_shared_landmarks) {
    if (last_end_ < f && !broken_before_) {
      // The frames since the last window would otherwise never be solved.
      const FrameRange closing{std::max(segment_begin_, f - o_.window_frames), f};
      if (closing.size() >= kMinClippedFrames) due.push_back(closing);
      last_end_ = f;
    }
    if (!broken_before_)
      GetLogger("system")->info("tracking break at frame {}: no window spans it", f);
    broken_before_ = true;
    segment_begin_ = f;
  } else {
    broken_before_ = false;
  }
  const int done = f + 1;
  if (done >= o_.window_frames && (done - o_.window_frames) % o_.window_every == 0) {
    if (auto w = Clip({done - o_.window_frames, done})) due.push_back(*w);
    last_end_ = done;
  }
  return due;
}

std::optional<FrameRange> WindowScheduler::Final(int frames_done) {
  if (frames_done <= 0 || last_end_ >= frames_done) return std::nullopt;
  last_end_ = frames_done;
  return Clip({std::max(0, frames_done - o_.window_frames), frames_done});
}

std::optional<FrameRange> WindowScheduler::Clip(FrameRange r) const {
  if (segment_begin_ <= r.begin) return r;
  if (r.end - segment_begin_ < kMinClippedFrames) return std::nullopt;
  return FrameRange{segment_begin_, r.end};
}

std::vector<FrameRange> SegmentsBetweenBreaks(const TrackletTable& table, int frames,
                                              const OnlineOptions& o) {
  std::vector<FrameRange> all;
  int begin = 0;
  for (int f = 1; f <= frames; ++f)
    if (f == frames || SharedWithPrevious(table, f) < o.min_shared_landmarks) {
      all.push_back({begin, f});
      begin = f;
    }
  if (all.size() <= 1) return all;
  std::vector<FrameRange> kept;
  for (const FrameRange& r : all)
    if (r.size() >= kMinClippedFrames) kept.push_back(r);
  GetLogger("system")->info("{} tracking break(s): {} stretch(es) long enough to solve",
                            all.size() - 1, kept.size());
  return kept;
}

}  // namespace cslam
