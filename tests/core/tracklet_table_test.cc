#include "core/tracklet_table.h"

#include <gtest/gtest.h>

#include <vector>

namespace cslam {
namespace {

const Eigen::Matrix3d kI = Eigen::Matrix3d::Identity();

TrackletTable Sample() {
  // landmark 0: frames 0..9; landmark 1: frames 5..14; landmark 2: frames 0,2,4,...,18.
  TrackletTable t;
  for (int f = 0; f < 20; ++f) {
    if (f < 10) t.Add(0, f, Eigen::Vector3d(f, 0, 0), kI);
    if (f >= 5 && f < 15) t.Add(1, f, Eigen::Vector3d(f, 1, 0), kI);
    if (f % 2 == 0) t.Add(2, f, Eigen::Vector3d(f, 2, 0), kI);
  }
  return t;
}

TEST(TrackletTable, CountsAndPerLandmarkOrder) {
  const TrackletTable t = Sample();
  EXPECT_EQ(t.num_landmarks(), 3);
  EXPECT_EQ(t.num_frames(), 19);
  EXPECT_EQ(t.num_observations(), 30u);
  int last = -1;
  for (const auto& o : t.ObservationsOf(2)) {
    EXPECT_GT(o.frame, last);
    last = o.frame;
  }
}

TEST(TrackletTable, RejectsADuplicateObservation) {
  TrackletTable t = Sample();
  EXPECT_FALSE(t.Add(0, 3, Eigen::Vector3d::Zero(), kI));
  EXPECT_EQ(t.num_observations(), 30u);
}

TEST(TrackletTable, OutOfOrderInsertKeepsFrameIndexConsistent) {
  TrackletTable t;
  t.Add(0, 5, Eigen::Vector3d(5, 0, 0), kI);
  t.Add(0, 1, Eigen::Vector3d(1, 0, 0), kI);
  t.Add(0, 3, Eigen::Vector3d(3, 0, 0), kI);
  for (int f : {1, 3, 5}) {
    ASSERT_EQ(t.ObservationsAt(f).size(), 1u);
    EXPECT_EQ(t.Get(t.ObservationsAt(f)[0]).frame, f);
    EXPECT_EQ(t.Get(t.ObservationsAt(f)[0]).x.x(), f);
  }
}

TEST(TrackletTable, WindowQueriesSeeOnlyTheRange) {
  const TrackletTable t = Sample();
  const auto w = t.ObservationsOf(0, {3, 7});
  ASSERT_EQ(w.size(), 4u);
  EXPECT_EQ(w.front().frame, 3);
  EXPECT_EQ(w.back().frame, 6);
  EXPECT_EQ(t.LandmarksIn({10, 15}), (std::vector<int>{1, 2}));
  EXPECT_EQ(t.LandmarksIn({0, 20}, 10), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(t.LandmarksIn({0, 6}, 3), (std::vector<int>{0, 2}));
}

TEST(TrackletTable, CoObservedFramesIsTheIntersection) {
  const TrackletTable t = Sample();
  EXPECT_EQ(t.CoObservedFrames(0, 1), (std::vector<int>{5, 6, 7, 8, 9}));
  EXPECT_EQ(t.CoObservedFrames(1, 2), (std::vector<int>{6, 8, 10, 12, 14}));
  EXPECT_EQ(t.CoObservedFrames(0, 1, {7, 100}), (std::vector<int>{7, 8, 9}));
}

TEST(TrackletTable, ObservationsAtAreSortedByLandmark) {
  const TrackletTable t = Sample();
  const auto& refs = t.ObservationsAt(6);
  ASSERT_EQ(refs.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(refs[i].landmark, i);
    EXPECT_EQ(t.Get(refs[i]).frame, 6);
  }
  EXPECT_TRUE(t.ObservationsAt(99).empty());
}

TEST(TrackletTable, SliceKeepsIdsAndOnlyTheRange) {
  const TrackletTable t = Sample();
  const TrackletTable s = t.Slice({8, 12});
  EXPECT_EQ(s.ObservationsOf(0).size(), 2u);
  EXPECT_EQ(s.ObservationsOf(1).size(), 4u);
  EXPECT_EQ(s.ObservationsOf(2).size(), 2u);
  EXPECT_EQ(s.num_observations(), 8u);
}

TEST(TrackletTable, CompactSliceRenumbersTheWindowsLandmarksInIdOrder) {
  const TrackletTable t = Sample();
  std::vector<int> ids;
  const TrackletTable s = t.CompactSlice({10, 16}, &ids);  // landmark 0 ends at frame 9
  EXPECT_EQ(ids, (std::vector<int>{1, 2}));
  ASSERT_EQ(s.num_landmarks(), 2);
  for (int local = 0; local < 2; ++local) {
    const auto want = t.ObservationsOf(ids[local], {10, 16});
    const auto got = s.ObservationsOf(local);
    ASSERT_EQ(got.size(), want.size());
    for (size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].landmark, local);
      EXPECT_EQ(got[k].frame, want[k].frame);
      EXPECT_EQ(got[k].x, want[k].x);
    }
  }
  // Frame refs address the renumbered observations, in ascending landmark order.
  ASSERT_EQ(s.ObservationsAt(12).size(), 2u);
  EXPECT_EQ(s.Get(s.ObservationsAt(12)[0]).landmark, 0);
  EXPECT_EQ(s.Get(s.ObservationsAt(12)[1]).x, Eigen::Vector3d(12, 2, 0));
  // An empty window holds nothing.
  const TrackletTable none = t.CompactSlice({30, 40}, &ids);
  EXPECT_TRUE(ids.empty());
  EXPECT_EQ(none.num_landmarks(), 0);
}

TEST(TrackletTable, SlicesKeepTheClippedMarkOfEachObservation) {
  TrackletTable t;
  for (int f = 0; f < 6; ++f) t.Add(3, f, Eigen::Vector3d(f, 0, 0), kI, /*clipped=*/f % 2 == 1);
  EXPECT_FALSE(t.ObservationsOf(3)[0].clipped);
  EXPECT_TRUE(t.ObservationsOf(3)[1].clipped);
  std::vector<int> ids;
  const TrackletTable compact = t.CompactSlice({2, 6}, &ids);
  const TrackletTable slice = t.Slice({2, 6});
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(compact.ObservationsOf(0)[k].clipped, k % 2 == 1) << k;
    EXPECT_EQ(slice.ObservationsOf(3)[k].clipped, k % 2 == 1) << k;
  }
}

TEST(TrackletTable, ForgetBeforeKeepsLaterFramesIntactAndSpansWhole) {
  TrackletTable t = Sample();
  const TrackletTable before = t;
  t.ForgetBefore(10);
  EXPECT_EQ(t.first_held_frame(), 10);
  for (int f = 0; f < 10; ++f) EXPECT_TRUE(t.ObservationsAt(f).empty());
  size_t held = 0;
  for (int f = 10; f < t.num_frames(); ++f) {
    ASSERT_EQ(t.ObservationsAt(f).size(), before.ObservationsAt(f).size());
    for (size_t k = 0; k < t.ObservationsAt(f).size(); ++k) {
      // Refs still address the same observation after each landmark lost its prefix.
      const StereoObservation& a = t.Get(t.ObservationsAt(f)[k]);
      const StereoObservation& b = before.Get(before.ObservationsAt(f)[k]);
      EXPECT_EQ(a.landmark, b.landmark);
      EXPECT_EQ(a.frame, f);
      EXPECT_EQ(a.x, b.x);
    }
    held += t.ObservationsAt(f).size();
  }
  EXPECT_EQ(t.num_observations(), held);
  EXPECT_LT(t.num_observations(), before.num_observations());
  for (int l = 0; l < t.num_landmarks(); ++l) {
    for (const StereoObservation& o : t.ObservationsOf(l)) EXPECT_GE(o.frame, 10);
    EXPECT_EQ(t.Span(l).first_frame, before.ObservationsOf(l).front().frame);
    EXPECT_EQ(t.Span(l).last_frame, before.ObservationsOf(l).back().frame);
    EXPECT_EQ(t.Span(l).observations, static_cast<int>(before.ObservationsOf(l).size()));
  }
  EXPECT_EQ(t.LandmarksIn({0, 10}).size(), 0u);
  EXPECT_EQ(t.LandmarksIn({10, 20}), before.LandmarksIn({10, 20}));
  // Tracks go on after forgetting, and a forgotten frame cannot be written again.
  EXPECT_TRUE(t.Add(1, t.num_frames(), Eigen::Vector3d(1, 2, 3), Eigen::Matrix3d::Identity()));
  EXPECT_EQ(t.Span(1).observations, static_cast<int>(before.ObservationsOf(1).size()) + 1);
  EXPECT_DEATH(t.Add(0, 3, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()), "forgotten frame");
}

TEST(SplitIntoChunks, OverlapsAndCoversEveryFrame) {
  const auto chunks = SplitIntoChunks(250, 100, 25);
  ASSERT_EQ(chunks.size(), 3u);
  EXPECT_EQ(chunks[0], (FrameRange{0, 100}));
  EXPECT_EQ(chunks[1], (FrameRange{75, 175}));
  EXPECT_EQ(chunks[2], (FrameRange{150, 250}));
  const auto tail = SplitIntoChunks(180, 100, 25);  // 150..180 is short: merged
  ASSERT_EQ(tail.size(), 2u);
  EXPECT_EQ(tail[1], (FrameRange{75, 180}));
  EXPECT_EQ(SplitIntoChunks(40, 100, 25).size(), 1u);
}

}  // namespace
}  // namespace cslam
