#include "backend/model_assignment.h"

#include <gtest/gtest.h>

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

Scene MakeTwoMovers(int frames) {
  Scene out;
  std::vector<TestBody> bodies(3);
  bodies[0].points_in_body = testing::RandomPoints(120, {-6, -2, 8}, {6, 2, 12}, 1);
  bodies[0].world_from_body = [](int) { return Pose::Identity(); };
  for (int b = 1; b <= 2; ++b) {
    bodies[b].points_in_body = testing::RandomPoints(30, {-0.8, -0.6, -0.8}, {0.8, 0.6, 0.8}, 10 + b);
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

  const ModelAssignment a = AssignToMotionModels(tracks, labels, est, ModelAssignmentOptions{});
  EXPECT_EQ(a.merges, 1);
  EXPECT_TRUE(a.outliers.empty());
  EXPECT_GE(a.reassigned, 5);
  EXPECT_EQ(testing::ClusteringAccuracy(a.labels, sc.s.truth), 1.0);
  for (int l = 0; l < static_cast<int>(labels.size()); ++l)
    if (sc.s.truth[l] == 0) EXPECT_EQ(a.labels[l], 0) << "landmark " << l;
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
  EXPECT_EQ(testing::ClusteringAccuracy(a.labels, sc.s.truth), 1.0);
}

TEST(ModelAssignment, CheckNamesTheBadKey) {
  ModelAssignmentOptions o;
  o.min_coverage = 0.0;
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("model_assignment.min_coverage"), std::string::npos);
  }
  o = ModelAssignmentOptions{};
  o.merge_ratio = 0.5;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
