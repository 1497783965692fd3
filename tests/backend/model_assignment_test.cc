#include "backend/model_assignment.h"

#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "tests/backend/test_scene.h"

namespace cslam {
namespace {

using testing::TestBody;
using testing::YawPose;

// A static wall 8-12 m away, split by the test into a left and a right piece, and two boxes
// moving across it (outdoor baseline, 1 px noise, covariance 1 px²).
struct Scene {
  testing::TestScene s;
  std::vector<std::function<Pose(int)>> world_from_body;
};

// A cluster `label` over the first mover's frames that holds still in the world.
void AddStillCluster(const Scene& sc, int label, MotionEstimate* est) {
  ClusterMotion still = est->clusters[0];
  still.cluster = label;
  for (size_t k = 0; k < still.frames.size(); ++k) {
    still.world_from_cluster[k] = Pose::Identity();
    still.cam_from_cluster[k] = sc.s.world_from_cam[still.frames[k]].inverse();
  }
  est->clusters.push_back(still);
}

Scene MakeTwoMovers(int frames, int mover_points = 30) {
  Scene out;
  std::vector<TestBody> bodies(3);
  bodies[0].points_in_body = testing::RandomPoints(120, {-6, -2, 8}, {6, 2, 12}, 1);
  bodies[0].world_from_body = [](int) { return Pose::Identity(); };
  for (int b = 1; b <= 2; ++b) {
    bodies[b].points_in_body =
        testing::RandomPoints(mover_points, {-0.8, -0.6, -0.8}, {0.8, 0.6, 0.8}, 10 + b);
    const double dir = b == 1 ? 1.0 : -1.0;
    bodies[b].world_from_body = [=](int t) {
      return YawPose(0.01 * dir * t, Eigen::Vector3d(-dir * 2.0 + dir * 0.08 * t, 0.5 * dir, 5.0));
    };
  }
  for (const auto& b : bodies) out.world_from_body.push_back(b.world_from_body);
  out.s = testing::MakeScene(testing::SyntheticCamera(true), bodies, frames,
                             [](int t) { return YawPose(0.003 * t, {0.0, 0.0, 0.05 * t}); },
                             1.0, 1.0, 7);
  return out;
}

// The exact motions of the bodies listed in `labels_of_body` ([body] → cluster label, -1 = no
// model), as EstimateMotions would return them with perfect estimation.
MotionEstimate TrueEstimate(const Scene& sc, const std::vector<int>& labels_of_body) {
  MotionEstimate e;
  const int frames = static_cast<int>(sc.s.world_from_cam.size());
  e.range = {0, frames};
  e.world_from_cam = sc.s.world_from_cam;
  for (size_t b = 1; b < labels_of_body.size(); ++b) {
    if (labels_of_body[b] < 0) continue;
    ClusterMotion m;
    m.cluster = labels_of_body[b];
    for (int t = 0; t < frames; ++t) {
      m.frames.push_back(t);
      m.world_from_cluster.push_back(sc.world_from_body[b](t));
      m.cam_from_cluster.push_back(sc.s.world_from_cam[t].inverse() * sc.world_from_body[b](t));
    }
    e.clusters.push_back(m);
  }
  std::sort(e.clusters.begin(), e.clusters.end(),
            [](const ClusterMotion& a, const ClusterMotion& b) { return a.cluster < b.cluster; });
  return e;
}

TEST(ModelAssignment, CostIsAboutOneUnderTheTrueMotionAndLargeUnderAnother) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  const MotionEstimate truth = TrueEstimate(sc, {0, 1, 2});
  double own = 0, wrong = 0;
  int n = 0;
  for (int l = 0; l < sc.s.table.num_landmarks(); ++l) {
    if (sc.s.truth[l] != 1) continue;
    own += ModelCost(tracks[l], truth, 1, 0.8);
    wrong += ModelCost(tracks[l], truth, 0, 0.8);
    ++n;
  }
  ASSERT_GT(n, 10);
  EXPECT_NEAR(own / n, 1.0, 0.3);  // reduced χ² of a correct model with exact covariances
  EXPECT_GT(wrong / n, 30.0);
}

TEST(ModelAssignment, MergesASplitBackgroundAndReassignsAMislabelledMover) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  // Input: the wall split into two clusters (0 and 3) by x; body 1 as cluster 1 but five of
  // its landmarks labelled static; body 2 as cluster 2.
  std::vector<int> labels = sc.s.truth;
  int moved = 0;
  for (int l = 0; l < static_cast<int>(labels.size()); ++l) {
    if (sc.s.truth[l] == 0 && tracks[l].samples.size() >= 4 && tracks[l].samples[0].point.x() > 0)
      labels[l] = 3;
    if (sc.s.truth[l] == 1 && moved < 5) labels[l] = 0, ++moved;
  }
  // The right piece of the wall gets its own (correct, static) motion.
  MotionEstimate est = TrueEstimate(sc, {0, 1, 2});
  ClusterMotion piece = est.clusters[0];
  piece.cluster = 3;
  for (size_t k = 0; k < piece.frames.size(); ++k) {
    piece.world_from_cluster[k] = Pose::Identity();
    piece.cam_from_cluster[k] = sc.s.world_from_cam[piece.frames[k]].inverse();
  }
  est.clusters.push_back(piece);
  // Landmark positions (for the motion test): static points in the world frame.
  est.landmark_in_cluster.assign(labels.size(), Eigen::Vector3d::Constant(NAN));
  for (size_t l = 0; l < labels.size(); ++l)
    if (sc.s.truth[l] == 0 && !tracks[l].samples.empty())
      est.landmark_in_cluster[l] =
          sc.s.world_from_cam[tracks[l].samples[0].frame] * tracks[l].samples[0].point;

  // The piece holds still: dissolved by the motion tests, its landmarks fit static. Without
  // them the merge test folds it in.
  ModelAssignmentOptions no_motion_test;
  no_motion_test.test_moving = false;
  no_motion_test.min_relative_motion = 0;
  for (const ModelAssignmentOptions& o : {ModelAssignmentOptions{}, no_motion_test}) {
    const ModelAssignment a = AssignToMotionModels(tracks, labels, est, o);
    EXPECT_EQ(a.dissolved, o.test_moving ? 1 : 0);
    EXPECT_EQ(a.merges, o.test_moving ? 0 : 1);
    EXPECT_TRUE(a.outliers.empty());
    EXPECT_GE(a.reassigned, 5);
    EXPECT_EQ(testing::ClusteringAccuracy(a.labels, sc.s.truth), 1.0);
    for (int l = 0; l < static_cast<int>(labels.size()); ++l)
      if (sc.s.truth[l] == 0) EXPECT_EQ(a.labels[l], 0) << "landmark " << l;
  }
}

TEST(ModelAssignment, LandmarksOfABodyWithoutAModelBecomeOutliers) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  // Body 2 merged into the static cluster and no model for it: its landmarks fit nothing.
  std::vector<int> labels = sc.s.truth;
  for (int& x : labels)
    if (x == 2) x = 0;
  const ModelAssignment a =
      AssignToMotionModels(tracks, labels, TrueEstimate(sc, {0, 1, -1}), ModelAssignmentOptions{});
  int body2 = 0, body2_outliers = 0;
  for (int l = 0; l < static_cast<int>(labels.size()); ++l) {
    if (sc.s.truth[l] != 2 || tracks[l].samples.size() < 4) continue;
    ++body2;
    body2_outliers += a.labels[l] == -1;
  }
  ASSERT_GT(body2, 10);
  EXPECT_EQ(body2_outliers, body2);
  EXPECT_EQ(static_cast<int>(a.outliers.size()), body2);
}

TEST(ModelAssignment, TwoMoversAreNotMergedWithEachOtherOrWithTheBackground) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  const ModelAssignment a =
      AssignToMotionModels(tracks, sc.s.truth, TrueEstimate(sc, {0, 1, 2}), ModelAssignmentOptions{});
  EXPECT_EQ(a.merges, 0);
  EXPECT_EQ(a.dissolved, 0);
  EXPECT_EQ(testing::ClusteringAccuracy(a.labels, sc.s.truth), 1.0);
}

TEST(ModelAssignment, ASmallRealMoverOfTenLandmarksIsKept) {
  const Scene sc = MakeTwoMovers(40, 10);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  const MotionEstimate truth = TrueEstimate(sc, {0, 1, 2});
  const ModelAssignment a = AssignToMotionModels(tracks, sc.s.truth, truth, ModelAssignmentOptions{});
  EXPECT_EQ(a.dissolved, 0);
  EXPECT_EQ(testing::ClusteringAccuracy(a.labels, sc.s.truth), 1.0);
}

TEST(ModelAssignment, RelativeMotionIsZeroForAClusterHeldStillAndLargeForAMover) {
  const Scene sc = MakeTwoMovers(40);
  MotionEstimate est = TrueEstimate(sc, {0, 1, 2});
  est.landmark_in_cluster.assign(sc.s.truth.size(), Eigen::Vector3d::Constant(NAN));
  for (size_t l = 0; l < sc.s.truth.size(); ++l)  // body points at frame 0, in the body frame
    est.landmark_in_cluster[l] = sc.world_from_body[sc.s.truth[l]](0).inverse() *
                                 (sc.s.world_from_cam[0] * Eigen::Vector3d(0, 0, 6 + 0.01 * l));
  // Body 1 sweeps 3.2 m in 40 frames at ~5 m: RMS ≈ 3.2 / √12 ≈ 0.9 m, i.e. ~0.2 of the range.
  EXPECT_GT(RelativeMotion(est, sc.s.truth, 1), 0.1);
  AddStillCluster(sc, 3, &est);
  std::vector<int> labels = sc.s.truth;
  for (size_t l = 0; l < labels.size(); l += 7)
    if (labels[l] == 0) labels[l] = 3;
  EXPECT_NEAR(RelativeMotion(est, labels, 3), 0.0, 1e-12);
  EXPECT_LT(RelativeMotion(est, labels, 4), 0.0);  // no such cluster
}

TEST(ModelAssignment, TheMovingTestPassesAMoverAndNotAPieceOfTheStaticWorld) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  MotionEstimate est = TrueEstimate(sc, {0, 1, 2});
  const MovingTestResult mover = TestClusterMoving(tracks, sc.s.truth, est, 1, {});
  EXPECT_TRUE(mover.moving);
  EXPECT_GT(mover.Statistic(), 10 * mover.threshold);
  // Every 7th static landmark given a cluster of its own that holds still.
  AddStillCluster(sc, 3, &est);
  std::vector<int> labels = sc.s.truth;
  for (size_t l = 0; l < labels.size(); l += 7)
    if (labels[l] == 0) labels[l] = 3;
  const MovingTestResult piece = TestClusterMoving(tracks, labels, est, 3, {});
  EXPECT_GT(piece.landmarks, 5);
  EXPECT_FALSE(piece.moving);
  EXPECT_NEAR(piece.Statistic(), 0.0, 1e-6);  // the same motion: the same χ²
  EXPECT_FALSE(TestClusterMoving(tracks, labels, est, 4, {}).moving);  // no such cluster
}

TEST(ModelAssignment, TheFinalCheckDissolvesAStillPieceIntoTheStaticWorldAndKeepsTheMovers) {
  const Scene sc = MakeTwoMovers(40);
  const PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  MotionEstimate est = TrueEstimate(sc, {0, 1, 2});
  AddStillCluster(sc, 3, &est);
  est.landmark_cluster = sc.s.truth;
  est.landmark_in_cluster.assign(sc.s.truth.size(), Eigen::Vector3d::Zero());
  std::vector<int> piece;
  for (size_t l = 0; l < est.landmark_cluster.size(); l += 7)
    if (est.landmark_cluster[l] == 0 && tracks[l].samples.size() >= 4) {
      est.landmark_cluster[l] = 3;
      piece.push_back(static_cast<int>(l));
    }
  ASSERT_GE(piece.size(), 5u);
  EXPECT_EQ(DissolveUnsupportedClusters(tracks, ModelAssignmentOptions{}, &est), 1);
  ASSERT_EQ(est.clusters.size(), 2u);
  // The static points are the scene's first 120 landmarks, fixed in the world.
  const std::vector<Eigen::Vector3d> world = testing::RandomPoints(120, {-6, -2, 8}, {6, 2, 12}, 1);
  for (int l : piece) {
    EXPECT_EQ(est.landmark_cluster[l], 0) << l;
    ASSERT_LT(l, 120);
    EXPECT_LT((est.landmark_in_cluster[l] - world[l]).norm(), 0.2) << l;  // where its track says
  }
  for (size_t l = 0; l < sc.s.truth.size(); ++l)
    if (sc.s.truth[l] >= 1) EXPECT_EQ(est.landmark_cluster[l], sc.s.truth[l]);
}

// Tracks that follow no physical point (each drifts its own way, like KLT on an occlusion
// boundary), grouped into a cluster by the re-clustering of outliers.
TEST(ModelAssignment, AGroupOfDriftingTracksIsDissolvedAndReclusteredOnlyUpToTheLimit) {
  const Scene sc = MakeTwoMovers(40);
  PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  std::vector<int> labels = sc.s.truth;
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<int> junk;
  for (int l = 0; l < static_cast<int>(labels.size()) && junk.size() < 12; ++l) {
    if (sc.s.truth[l] != 0 || tracks[l].samples.size() < 20) continue;
    const Eigen::Vector3d drift = 0.05 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    for (size_t k = 0; k < tracks[l].samples.size(); ++k)
      tracks[l].samples[k].point += static_cast<double>(k) * drift;
    labels[l] = 3;
    junk.push_back(l);
  }
  ASSERT_EQ(junk.size(), 12u);
  // The group's motion: whatever the estimator made of it (here body 1's: no better or worse).
  MotionEstimate est = TrueEstimate(sc, {0, 1, 2});
  ClusterMotion group = est.clusters[0];
  group.cluster = 3;
  est.clusters.push_back(group);

  std::vector<int> reclusterings(tracks.size(), 0);
  const ModelAssignmentOptions o;
  ModelAssignment a = AssignToMotionModels(tracks, labels, est, o, &reclusterings);
  EXPECT_EQ(a.dissolved, 1);
  EXPECT_EQ(a.outliers, junk);  // handed out again: this was their first group
  for (int l : junk) EXPECT_EQ(reclusterings[l], 1);
  EXPECT_EQ(a.unexplained, 0);

  for (int l : junk) reclusterings[l] = o.max_reclusterings;
  a = AssignToMotionModels(tracks, labels, est, o, &reclusterings);
  EXPECT_EQ(a.dissolved, 1);
  EXPECT_TRUE(a.outliers.empty());
  EXPECT_EQ(a.unexplained, 12);
  for (int l : junk) EXPECT_EQ(a.labels[l], -1);
  for (int l = 0; l < static_cast<int>(labels.size()); ++l)
    if (labels[l] != 3) EXPECT_EQ(a.labels[l], sc.s.truth[l]) << "landmark " << l;

  // Without the dissolution the group stays a "moving" cluster of its own. (The moving test
  // would dissolve it too: a motion that explains its tracks worse than the static world's.)
  EXPECT_FALSE(TestClusterMoving(tracks, labels, est, 3, o.moving_test).moving);
  ModelAssignmentOptions old = o;
  old.min_cluster_landmarks = 0;
  old.core_cluster_landmarks = 0;
  old.test_moving = false;
  a = AssignToMotionModels(tracks, labels, est, old, &reclusterings);
  EXPECT_EQ(a.dissolved, 0);
}

TEST(ModelAssignment, TrimmedCostLeavesOutOneJumpedSample) {
  const Scene sc = MakeTwoMovers(40);
  PointTracks tracks = BackProjectTracks(sc.s.table, sc.s.camera, {0, 40});
  const MotionEstimate truth = TrueEstimate(sc, {0, 1, 2});
  int l = 0;
  while (sc.s.truth[l] != 0 || tracks[l].samples.size() < 20) ++l;
  PointSample& s = tracks[l].samples[10];
  const Eigen::Matrix3d l_factor = s.cov.llt().matrixL();
  s.point += 30.0 * (l_factor * Eigen::Vector3d(1, 0, 0));  // a 30σ jump
  EXPECT_GT(ModelCost(tracks[l], truth, 0, 0.8), 3.0);
  EXPECT_LT(ModelCost(tracks[l], truth, 0, 0.8, 1), 2.0);
}

TEST(ModelAssignment, CheckNamesTheBadKey) {
  ModelAssignmentOptions o;
  o.min_coverage = 0.0;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("min_coverage"), std::string::npos);
  }
  o = ModelAssignmentOptions{};
  o.merge_ratio = 0.5;
  EXPECT_THROW(o.Check(), ConfigError);
  o = ModelAssignmentOptions{};
  o.max_reclusterings = 0;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("max_reclusterings"), std::string::npos);
  }
  o = ModelAssignmentOptions{};
  o.moving_test.false_alarm = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = ModelAssignmentOptions{};
  o.min_relative_motion = -1;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
