#include "core/tracklet_table.h"

#include <gtest/gtest.h>

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
