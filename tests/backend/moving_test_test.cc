#include "backend/moving_test.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "core/errors.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

// A stereo-like covariance at camera-frame point x: `lateral` m across the ray, the depth σ
// of a `disparity_px` disparity error with focal 700 px and baseline 0.5 m (σ_z = z² σ_d / f b).
Eigen::Matrix3d StereoCov(const Eigen::Vector3d& x, double lateral, double disparity_px) {
  const double sz = x.z() * x.z() * disparity_px / (700.0 * 0.5);
  const Eigen::Vector3d ray = x.normalized();
  Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - ray * ray.transpose();
  return lateral * lateral * across + sz * sz * ray * ray.transpose();
}

// Tracks of `points` (body frame) on a body at world_from_body[t], seen by a camera driving
// along z at `camera_speed` m per frame, with noise drawn from the stated covariance.
struct Cluster {
  std::vector<Pose> world_from_cam;
  std::vector<Pose> world_from_body;
  PointTracks tracks;
  std::vector<const PointTrack*> Pointers() const {
    std::vector<const PointTrack*> p;
    for (const PointTrack& t : tracks) p.push_back(&t);
    return p;
  }
};

Cluster MakeCluster(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& velocity,
                    int frames, double disparity_px, unsigned seed, double camera_speed = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Cluster c;
  for (int t = 0; t < frames; ++t) {
    Pose cam = Pose::Identity();
    cam.translation() = Eigen::Vector3d(0, 0, camera_speed * t);
    c.world_from_cam.push_back(cam);
    Pose body = Pose::Identity();
    body.translation() = velocity * t;
    c.world_from_body.push_back(body);
  }
  for (const Eigen::Vector3d& p : points) {
    PointTrack track;
    for (int t = 0; t < frames; ++t) {
      const Eigen::Vector3d x = c.world_from_cam[t].inverse() * (c.world_from_body[t] * p);
      const Eigen::Matrix3d cov = StereoCov(x, 0.01 * x.z() / 10.0, disparity_px);
      const Eigen::Matrix3d l = cov.llt().matrixL();
      const Eigen::Vector3d e = testing::Draw3([&] { return normal(rng); });
      track.samples.push_back({t, x + l * e, cov});
    }
    c.tracks.push_back(track);
  }
  return c;
}

std::vector<Eigen::Vector3d> Box(const Eigen::Vector3d& centre, int n) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i)
    p.push_back(centre + Eigen::Vector3d(0.4 * (i % 3) - 0.4, 0.3 * ((i / 3) % 3) - 0.3,
                                         0.5 * (i % 2)));
  return p;
}

// cam → world and cam → body lookups of a cluster.
struct Models {
  std::vector<Pose> static_poses, own_poses;
  ModelPose Static() const {
    return [this](int f) { return f < static_cast<int>(static_poses.size()) ? &static_poses[f] : nullptr; };
  }
  ModelPose Own() const {
    return [this](int f) { return f < static_cast<int>(own_poses.size()) ? &own_poses[f] : nullptr; };
  }
};

Models TrueModels(const Cluster& c) {
  Models m;
  for (size_t t = 0; t < c.world_from_cam.size(); ++t) {
    m.static_poses.push_back(c.world_from_cam[t]);
    m.own_poses.push_back(c.world_from_body[t].inverse() * c.world_from_cam[t]);
  }
  return m;
}

TEST(ChiSquareUpperQuantile, MatchesTabulatedValues) {
  EXPECT_NEAR(ChiSquareUpperQuantile(6, 0.05), 12.592, 0.01 * 12.592);
  EXPECT_NEAR(ChiSquareUpperQuantile(10, 0.001), 29.588, 0.01 * 29.588);
  EXPECT_NEAR(ChiSquareUpperQuantile(100, 0.001), 149.449, 0.005 * 149.449);
  EXPECT_NEAR(ChiSquareUpperQuantile(100, 0.5), 99.334, 0.005 * 99.334);
}

TEST(MovingTest, ACarDrivingAtWalkingPaceTenMetresAheadIsMoving) {
  const Cluster c = MakeCluster(Box({2, 0, 10}, 8), {0, 0, 1.15}, 20, 0.5, 1);
  const Models m = TrueModels(c);
  const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
  EXPECT_EQ(r.landmarks, 8);
  EXPECT_EQ(r.frames, 20);
  EXPECT_EQ(r.dof, 6 * 19);
  EXPECT_TRUE(r.moving) << r.Statistic() << " vs " << r.threshold;
}

// The own motion of a static piece, estimated from its noisy tracks, is the static motion
// plus what the noise suggests. Here: the static motion plus a per-frame shift of the size a
// fit over 8 points leaves (σ/√8 in each axis).
TEST(MovingTest, AStaticPieceWhoseOwnMotionFitItsNoiseIsNotMoving) {
  int moving = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Cluster c = MakeCluster(Box({2, 0, 10}, 8), Eigen::Vector3d::Zero(), 20, 0.5, seed);
    Models m = TrueModels(c);
    std::mt19937 rng(100 + seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (size_t t = 0; t < m.own_poses.size(); ++t) {
      const Eigen::Vector3d x(2, 0, 10.0 - t);
      const Eigen::Matrix3d l = (StereoCov(x, 0.01, 0.5) / 8.0).llt().matrixL();
      Pose jitter = Pose::Identity();
      jitter.translation() = l * testing::Draw3([&] { return normal(rng); });
      m.own_poses[t] = jitter * m.own_poses[t];
    }
    const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
    moving += r.moving;
  }
  EXPECT_EQ(moving, 0);
}

// 0.5 m of motion along the line of sight is 5 σ of depth at 8 m and a few hundredths of one
// σ at 100 m (camera standing): the test must see the near body and must not see the far one.
TEST(MovingTest, ADepthDriftPassesNearAndNotFar) {
  const Eigen::Vector3d drift(0, 0, 0.5 / 19.0);  // per frame, along the line of sight
  const Cluster near = MakeCluster(Box({1, 0, 8}, 9), drift, 20, 0.5, 3, 0.0);
  const Cluster far = MakeCluster(Box({1, 0, 100}, 9), drift, 20, 0.5, 3, 0.0);
  EXPECT_TRUE(TestMoving(near.Pointers(), TrueModels(near).Static(), TrueModels(near).Own(), {}).moving);
  const Models fm = TrueModels(far);
  const MovingTestResult r = TestMoving(far.Pointers(), fm.Static(), fm.Own(), {});
  EXPECT_FALSE(r.moving) << r.Statistic() << " vs " << r.threshold;
}

// A track that jumps by a metre in a few frames (KLT slid along an edge) and an own motion
// that follows the jump: the capped χ² keeps the jump from deciding the test.
TEST(MovingTest, OneJumpingTrackDoesNotMakeAStaticPieceMove) {
  Cluster c = MakeCluster(Box({2, 0, 10}, 8), Eigen::Vector3d::Zero(), 20, 0.5, 5);
  Models m = TrueModels(c);
  for (int t = 10; t < 13; ++t) c.tracks[0].samples[t].point += Eigen::Vector3d(1.0, 0, 0);
  const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
  EXPECT_GT(r.chi2_static, 3 * 16.0);  // the jump is there, capped
  EXPECT_FALSE(r.moving);
}

// Corners along the edge of a saturated surface slide alike as the exposure changes, and a
// cluster of them has an own motion that follows the slide: that is motion to the test
// unless the frontend marks the samples clipped.
TEST(MovingTest, SamplesOnClippedPixelsAreNoEvidenceOfMotion) {
  Cluster c = MakeCluster(Box({2, 0, 10}, 8), {0.05, 0, 0}, 20, 0.5, 9);
  const Models m = TrueModels(c);
  EXPECT_TRUE(TestMoving(c.Pointers(), m.Static(), m.Own(), {}).moving);
  for (PointTrack& t : c.tracks)
    for (PointSample& s : t.samples) s.clipped = true;
  const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
  EXPECT_EQ(r.landmarks, 0);
  EXPECT_FALSE(r.moving);
}

TEST(MovingTest, ACarWithSomeClippedCornersIsStillMoving) {
  Cluster c = MakeCluster(Box({2, 0, 10}, 8), {0, 0, 1.15}, 20, 0.5, 1);
  for (size_t i = 0; i < c.tracks.size(); i += 2)
    for (PointSample& s : c.tracks[i].samples) s.clipped = true;
  const Models m = TrueModels(c);
  const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
  EXPECT_EQ(r.landmarks, 4);
  EXPECT_TRUE(r.moving);
}

TEST(MovingTest, FramesWithFewLandmarksCountFewerUnknowns) {
  Cluster c = MakeCluster(Box({2, 0, 10}, 3), Eigen::Vector3d::Zero(), 10, 0.5, 7);
  c.tracks[2].samples.resize(5);  // frames 0..2 hold 3 landmarks, 3..4 two, 5..9 one
  c.tracks[1].samples.resize(3);
  const Models m = TrueModels(c);
  const MovingTestResult r = TestMoving(c.Pointers(), m.Static(), m.Own(), {});
  EXPECT_EQ(r.dof, 3 * 6 + 2 * 5 + 5 * 3 - 6);
}

TEST(MovingTestOptions, CheckNamesTheKey) {
  MovingTestOptions o;
  o.false_alarm = 1.5;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("false_alarm"), std::string::npos);
  }
}

}  // namespace
}  // namespace cslam
