#include "system/pipeline/window_scheduler.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace cslam {
namespace {

// `frames` frames where ten landmarks are seen throughout, except that none survives into
// frame `break_at` (a jump): new landmarks start there.
TrackletTable Tracks(int frames, int break_at) {
  TrackletTable t;
  for (int f = 0; f < frames; ++f)
    for (int k = 0; k < 10; ++k) t.Add((f < break_at ? 0 : 10) + k, f, Eigen::Vector3d(k, 0, 0), Eigen::Matrix3d::Identity());
  return t;
}

std::vector<FrameRange> Schedule(const TrackletTable& t, int frames, const OnlineOptions& o) {
  WindowScheduler s(o);
  std::vector<FrameRange> all;
  for (int f = 0; f < frames; ++f)
    for (const FrameRange& w : s.AfterFrame(t, f)) all.push_back(w);
  if (auto w = s.Final(frames)) all.push_back(*w);
  return all;
}

TEST(WindowScheduler, RunsTheLastWindowFramesEveryFewFramesAndOnceMoreAtTheEnd) {
  OnlineOptions o;
  o.window_frames = 10;
  o.window_every = 4;
  const std::vector<FrameRange> w = Schedule(Tracks(20, 100), 20, o);
  const std::vector<FrameRange> want = {{0, 10}, {4, 14}, {8, 18}, {10, 20}};
  EXPECT_EQ(w, want);
}

TEST(WindowScheduler, NoWindowSpansATrackingBreak) {
  OnlineOptions o;
  o.window_frames = 10;
  o.window_every = 4;
  const TrackletTable t = Tracks(30, 15);
  EXPECT_EQ(SharedWithPrevious(t, 14), 10);
  EXPECT_EQ(SharedWithPrevious(t, 15), 0);
  const std::vector<FrameRange> w = Schedule(t, 30, o);
  for (const FrameRange& r : w) EXPECT_FALSE(r.begin < 15 && r.end > 15) << r.begin << ".." << r.end;
  // The stretch before the break is closed by a window of its own.
  EXPECT_NE(std::find(w.begin(), w.end(), FrameRange{5, 15}), w.end());
  const std::vector<FrameRange> segments = SegmentsBetweenBreaks(t, 30, o);
  EXPECT_EQ(segments, (std::vector<FrameRange>{{0, 15}, {15, 30}}));
}

}  // namespace
}  // namespace cslam
