// The frontend on 10 real frames of KITTI raw drive 0005 (city street, a van and a cyclist
// moving ahead of the car).
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "tests/frontend/kitti_images.h"

namespace cslam {
namespace {

constexpr int kFrames = 10;
// The frontend with default options continues 415–571 tracks into each of frames 1–9 (fewest
// at frames 1 and 9, where the car pitches over a bump); 330 leaves ~20 % margin and still
// fails a frontend that loses half of its tracks. Frame 0 starts 610 of its 1 485 corners and
// frames 1–9 hold 646–758 live tracks after the top-up. (Before the matcher refused corners
// with a second acceptable match, StereoMatcherOptions::unique_match, these were 559–782
// tracked, 838 started and 910–963 live: the corners of dashed lines, railings and rows of
// windows on this street are now left out. Before a tracked point's uniqueness was checked
// over the whole disparity range rather than near its last disparity, 481–664 tracked and
// 690–832 live: a track ends where the pattern's other period comes into view.)
constexpr int kMinTrackedPerFrame = 330;
constexpr int kMinStartedAtFrame0 = 500;
constexpr int kMinLiveAfterTopUp = 520;
// On odometry clip_a (faster: ~1.2 m per frame) the same frontend continues 440–551 tracks
// into each of frames 1–9 (558–670 before the whole-range uniqueness check); 350 keeps the
// same ~20 % margin.
constexpr int kMinTrackedOnClipA = 350;

class FrontendOnKitti : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int i = 0; i < kFrames; ++i) {
      pairs_.push_back(testing::LoadDrive0005Pair(i));
      if (pairs_.back().left.empty() || pairs_.back().right.empty())
        GTEST_SKIP() << "KITTI drive 0005 not found under " << testing::Drive0005Dir();
    }
    StereoFrontend frontend(testing::Drive0005Camera(), FrontendOptions{});
    for (int i = 0; i < kFrames; ++i) {
      summaries_.push_back(frontend.Process(i, pairs_[i].left, pairs_[i].right, &table_));
      observations_after_.push_back(table_.num_observations());
    }
  }
  std::vector<testing::StereoPair> pairs_;
  TrackletTable table_;
  std::vector<FrameSummary> summaries_;
  std::vector<size_t> observations_after_;
};

TEST_F(FrontendOnKitti, TracksEnoughLandmarksIntoEveryFrame) {
  EXPECT_GE(summaries_[0].created, kMinStartedAtFrame0);
  for (int t = 1; t < kFrames; ++t) {
    EXPECT_GE(summaries_[t].tracked, kMinTrackedPerFrame) << "frame " << t;
    // Detection tops the live set back up towards the target.
    EXPECT_GE(summaries_[t].tracked + summaries_[t].created, kMinLiveAfterTopUp) << "frame " << t;
  }
}

TEST_F(FrontendOnKitti, TriangulatedDepthIsPositiveAndPlausible) {
  const StereoCamera cam = testing::Drive0005Camera();
  std::vector<double> depths;
  for (int id = 0; id < table_.num_landmarks(); ++id)
    for (const StereoObservation& o : table_.ObservationsOf(id)) {
      Eigen::Vector3d p;
      ASSERT_TRUE(cam.BackProject<double>(o.x, &p)) << "landmark " << id << " frame " << o.frame;
      ASSERT_GT(p.z(), 0.0);
      depths.push_back(p.z());
      EXPECT_TRUE(cam.InImage(o.x));
    }
  ASSERT_FALSE(depths.empty());
  std::sort(depths.begin(), depths.end());
  // A city street: most structure within a few tens of metres; nothing nearer than the
  // largest disparity allows (fx·b / 160 px ≈ 2.4 m).
  EXPECT_GT(depths.front(), 2.0);
  EXPECT_GT(depths[depths.size() / 2], 4.0);
  EXPECT_LT(depths[depths.size() / 2], 40.0);
}

TEST_F(FrontendOnKitti, CoversTheImageEvenly) {
  const StereoCamera cam = testing::Drive0005Camera();
  for (int t = 0; t + 1 < kFrames; ++t) {
    const auto& refs = table_.ObservationsAt(t);
    ASSERT_FALSE(refs.empty()) << "frame " << t;
    int left = 0, top = 0;
    std::vector<int> cells(8 * 4, 0);  // 8 columns × 4 rows
    for (const ObservationRef& r : refs) {
      const Eigen::Vector3d& x = table_.Get(r).x;
      left += x(0) < cam.width / 2.0;
      top += x(1) < cam.height / 2.0;
      ++cells[std::min(3, static_cast<int>(4 * x(1) / cam.height)) * 8 +
              std::min(7, static_cast<int>(8 * x(0) / cam.width))];
    }
    const double n = static_cast<double>(refs.size());
    EXPECT_GT(left / n, 0.3) << "frame " << t;
    EXPECT_LT(left / n, 0.7) << "frame " << t;
    EXPECT_GT(top / n, 0.2) << "frame " << t;
    EXPECT_LT(top / n, 0.8) << "frame " << t;
    EXPECT_GE(std::count_if(cells.begin(), cells.end(), [](int c) { return c > 0; }), 28)
        << "frame " << t << ": most of the 32 coarse cells hold observations";
  }
}

TEST_F(FrontendOnKitti, ObservationsGrowByWhatEachFrameReports) {
  size_t expected = 0;
  for (int t = 0; t < kFrames; ++t) {
    expected += summaries_[t].observations;
    EXPECT_EQ(observations_after_[t], expected) << "frame " << t;
    if (t > 0) {
      EXPECT_GT(observations_after_[t], observations_after_[t - 1]);
    }
    // tracked points always extend an existing landmark; confirmed new ones add two.
    EXPECT_EQ(summaries_[t].observations, summaries_[t].tracked + summaries_[t].new_landmarks);
  }
  EXPECT_EQ(observations_after_[0], 0u) << "frame 0 tracks wait for confirmation";
  for (int t = 0; t + 1 < kFrames; ++t)
    EXPECT_EQ(static_cast<int>(table_.ObservationsAt(t).size()),
              summaries_[t].tracked + summaries_[t + 1].new_landmarks);
  for (int id = 0; id < table_.num_landmarks(); ++id) {
    const auto obs = table_.ObservationsOf(id);
    ASSERT_GE(obs.size(), 2u) << "no single-frame landmark reaches the table";
    for (size_t k = 1; k < obs.size(); ++k) ASSERT_EQ(obs[k].frame, obs[k - 1].frame + 1);
  }
}

TEST(FrontendOnKittiOdometry, TracksThroughTheResidentialClip) {
  // A second camera, image size and scene (odometry clip_a, 1226×370, straight residential
  // street): the defaults must carry over.
  StereoFrontend frontend(testing::ClipACamera(), FrontendOptions{});
  TrackletTable table;
  int min_tracked = 1 << 30;
  for (int i = 0; i < kFrames; ++i) {
    const testing::StereoPair pair = testing::LoadClipAPair(i);
    if (pair.left.empty() || pair.right.empty()) GTEST_SKIP() << "KITTI odometry clip_a not found";
    const FrameSummary s = frontend.Process(i, pair.left, pair.right, &table);
    if (i > 0) min_tracked = std::min(min_tracked, s.tracked);
  }
  EXPECT_GE(min_tracked, kMinTrackedOnClipA);
}

}  // namespace
}  // namespace cslam
