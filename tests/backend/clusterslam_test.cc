#include "backend/clusterslam.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "backend/labelling.h"
#include "backend/point_tracks.h"
#include "core/errors.h"
#include "tests/backend/fake_motion_estimator.h"
#include "tests/backend/synthetic_bodies.h"
#include "tests/backend/test_scene.h"

namespace cslam {
namespace {

using testing::TestBody;
using testing::YawPose;

// A static wall patch 4-5 m away and `num_moving` bodies crossing in front of it in opposite
// directions, seen with the 0.5 m baseline, clustered with the indoor preset (ε = 60), pixel
// covariance 1.5² px². Why this geometry: under Eq. 1 as specified, (1) static pairs more than
// about 500 px apart exceed ε through the image prior alone (α·|Δx|²/(2·1.5²)), so complete
// linkage splits a background that fills the image — the patch spans ±190 px; (2) with the
// 0.1 m baseline the first term barely sees metre-scale motions at 3-5 m (measured: its value
// for static-moving pairs stays below ~10, the image prior gives the rest), so the bodies
// would merge into the background.
testing::TestScene MultiBody(int num_moving, int frames, double noise_px, unsigned seed) {
  std::vector<TestBody> bodies(1 + num_moving);
  bodies[0].points_in_body = testing::RandomPoints(80, {-1.2, -0.6, 4}, {1.2, 0.6, 5}, seed);
  bodies[0].world_from_body = [](int) { return Pose::Identity(); };
  for (int b = 1; b <= num_moving; ++b) {
    bodies[b].points_in_body =
        testing::RandomPoints(25, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}, seed + b);
    const double dir = b % 2 ? 1.0 : -1.0;
    const double y = -0.5 + 1.0 * (b - 1);
    bodies[b].world_from_body = [=](int t) {
      return YawPose(0.01 * dir * t, Eigen::Vector3d(-dir * 1.0 + dir * 0.015 * t, y, 2.5 + 0.3 * b));
    };
  }
  return testing::MakeScene(testing::SyntheticCamera(true), bodies, frames,
                            [](int t) { return YawPose(0.002 * t, {0.0, 0.0, 0.01 * t}); },
                            noise_px, 1.5, seed + 100);
}

// The paper's loop: Eq. 1 with its α, re-clustered every iteration (no model assignment).
ClusterSlamOptions PaperIndoor() {
  ClusterSlamOptions o = ClusterSlamOptions::Indoor();
  o.distance.alpha = 4e-4;
  o.assignment.enabled = false;
  o.convergence_vi = 0.0;
  return o;
}

TEST(ClusterSlam, TwoRigidBodiesWithoutNoiseGiveExactlyTwoClusters) {
  const auto s = MultiBody(1, 150, 0.0, 1);
  const FrameRange range{0, 150};
  const PointTracks tracks = BackProjectTracks(s.table, s.camera, range);
  const ClusterSlamOptions o = PaperIndoor();
  ASSERT_EQ(ChunksOf(range, o.consensus).size(), 2u);
  const auto labels = ClusterLandmarks(s.table, tracks, range, o, nullptr);
  EXPECT_EQ(LabellingVariation(labels, s.truth), 0.0);
  EXPECT_EQ(labels[0], 0);  // the background has the most observations: static
  EXPECT_EQ(*std::max_element(labels.begin(), labels.end()), 1);
}

TEST(ClusterSlam, LoopConvergesToTheTruePartitionOnANoisyMultiBodyScene) {
  const auto s = MultiBody(2, 150, 0.5, 2);
  const BackendResult r = RunClusterSlam(s.table, s.camera, {0, 150}, PaperIndoor(),
                                         testing::FakeEstimateMotions);
  const auto& labels = r.estimate.landmark_cluster;
  EXPECT_GE(testing::ClusteringAccuracy(labels, s.truth), 0.97);
  EXPECT_EQ(labels[0], 0);
  ASSERT_GE(r.iterations.size(), 2u);
  EXPECT_LE(r.iterations.size(), 5u);
  EXPECT_EQ(r.iterations.back().vi_to_previous, 0.0) << "did not converge";
  EXPECT_EQ(r.iterations.back().num_clusters, 3);
  EXPECT_EQ(r.method, "clusterslam");
  ASSERT_EQ(r.estimate.clusters.size(), 2u);
}

TEST(ClusterSlam, RefinedPositionsRecoverWhatTheFirstIterationMisses) {
  // In these scenes the camera-frame back-projections of iteration 1 leave part of a body
  // mislabelled; iteration 2 sees the refined positions (prediction + windowed residual, in
  // the camera frame) and gets every landmark right. With refine_half_window = 0 (raw
  // back-projections again) the labelling cannot change, and the loop stops at iteration 2.
  for (unsigned seed : {4u, 5u}) {
    const auto s = MultiBody(2, 150, 1.0, seed);
    const FrameRange range{0, 150};
    ClusterSlamOptions o = PaperIndoor();
    const auto first = ClusterLandmarks(s.table, BackProjectTracks(s.table, s.camera, range),
                                        range, o, nullptr);
    ASSERT_LT(testing::ClusteringAccuracy(first, s.truth), 0.95) << "scene too easy, seed " << seed;
    const BackendResult refined = RunClusterSlam(s.table, s.camera, range, o,
                                                 testing::FakeEstimateMotions);
    EXPECT_EQ(testing::ClusteringAccuracy(refined.estimate.landmark_cluster, s.truth), 1.0)
        << "seed " << seed;
    o.refine_half_window = 0;
    const BackendResult raw = RunClusterSlam(s.table, s.camera, range, o,
                                             testing::FakeEstimateMotions);
    EXPECT_EQ(raw.iterations.size(), 2u);
    EXPECT_EQ(LabellingVariation(raw.estimate.landmark_cluster, first), 0.0);
  }
}

// A tenth of the background's tracks drift through the image, each its own way (KLT on an
// occlusion boundary or foliage): they fit neither the static world nor any rigid motion.
TrackletTable WithDriftingTracks(const testing::TestScene& s, int every, unsigned seed,
                                 std::vector<int>* drifting) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  TrackletTable out;
  for (int l = 0; l < s.table.num_landmarks(); ++l) {
    const bool drift = s.truth[l] == 0 && l % every == 0;
    if (drift) drifting->push_back(l);
    const double a = angle(rng);
    const Eigen::Vector3d velocity = 0.4 * Eigen::Vector3d(std::cos(a), std::sin(a), std::cos(a));
    const auto obs = s.table.ObservationsOf(l);
    for (const StereoObservation& o : obs)
      out.Add(l, o.frame, drift ? Eigen::Vector3d(o.x + (o.frame - obs.front().frame) * velocity) : o.x,
              o.cov);
  }
  return out;
}

TEST(ClusterSlam, DriftingStaticTracksDoNotBecomeMovingClustersAndTheMoverIsFound) {
  const auto s = MultiBody(1, 60, 0.5, 5);
  std::vector<int> drifting;
  const TrackletTable table = WithDriftingTracks(s, 10, 6, &drifting);
  ASSERT_GE(drifting.size(), 8u);
  const FrameRange range{0, 60};
  const BackendResult r = RunClusterSlam(table, s.camera, range, ClusterSlamOptions::Indoor());
  const std::vector<int>& labels = r.estimate.landmark_cluster;
  std::map<int, int> mover_labels, moving_clusters;
  int mover = 0;
  for (int l = 0; l < static_cast<int>(s.truth.size()); ++l) {
    if (labels[l] >= 1) ++moving_clusters[labels[l]];
    if (s.truth[l] == 1) ++mover, ++mover_labels[labels[l]];
  }
  int best = 0;
  for (const auto& [label, n] : mover_labels)
    if (label >= 1) best = std::max(best, n);
  EXPECT_GE(best, 0.9 * mover) << "the mover is one cluster";
  EXPECT_EQ(moving_clusters.size(), 1u) << "no cluster made of drifting tracks";
  for (int l : drifting) EXPECT_LE(labels[l], 0) << "landmark " << l;
}

TEST(ClusterSlam, MotionPriorSmoothsTheObjectsWithoutChangingTheClustering) {
  testing::BodySceneSpec spec;
  spec.outdoor = true;
  spec.points_per_body = 15;
  spec.pixel_sigma = 1.0;
  spec.seed = 4;
  const testing::BodyScene scene = testing::MakeBodyScene(spec);
  const FrameRange range{0, spec.num_frames};
  ClusterSlamOptions without = ClusterSlamOptions::Outdoor();
  ClusterSlamOptions with = without;
  with.motion.bundle_adjustment.motion_prior_sigma_m = 0.05;
  with.motion.bundle_adjustment.motion_prior_sigma_rad = 0.01;
  const BackendResult a = RunClusterSlam(scene.table, scene.camera, range, without);
  const BackendResult b = RunClusterSlam(scene.table, scene.camera, range, with);
  // The prior is the last step, after the labels are settled: the same clusters come out.
  EXPECT_EQ(a.estimate.landmark_cluster, b.estimate.landmark_cluster);
  for (int k = 0; k < spec.num_frames; ++k)
    EXPECT_TRUE(a.estimate.world_from_cam[k].isApprox(b.estimate.world_from_cam[k], 0.0)) << k;
  // Each moving cluster's trajectory: the body it mostly holds, its step error with and without.
  std::set<int> bodies_found;
  for (const ClusterMotion& m : a.estimate.clusters) {
    std::map<int, int> votes;
    for (size_t i = 0; i < scene.labels.size(); ++i)
      if (a.estimate.landmark_cluster[i] == m.cluster) ++votes[scene.labels[i]];
    const int body = std::max_element(votes.begin(), votes.end(), [](auto x, auto y) {
                       return x.second < y.second;
                     })->first;
    if (body == 0) continue;
    bodies_found.insert(body);
    const double e_without = testing::CentroidStepError(scene, a.estimate, m.cluster, body);
    const double e_with = testing::CentroidStepError(scene, b.estimate, m.cluster, body);
    std::printf("cluster %d (body %d): step error %.4f -> %.4f m\n", m.cluster, body, e_without, e_with);
    EXPECT_LT(e_with, 0.6 * e_without) << "cluster " << m.cluster;
  }
  EXPECT_EQ(bodies_found.size(), 2u);
}

TEST(ClusterSlam, PresetsAndAblations) {
  EXPECT_EQ(ClusterSlamOptions::Indoor().hac.epsilon, 60.0);
  EXPECT_EQ(ClusterSlamOptions::Outdoor().hac.epsilon, 90.0);
  EXPECT_EQ(ClusterSlamOptions::Outdoor().consensus.chunk_length, 200);
  EXPECT_EQ(ClusterSlamOptions::Outdoor().consensus.chunk_overlap, 25);
  ClusterSlamOptions o;
  o.ablation = ClusterSlamAblation::kNoUncertainty;
  EXPECT_FALSE(o.Effective().distance.use_uncertainty);
  o.ablation = ClusterSlamAblation::kNoImagePrior;
  EXPECT_FALSE(o.Effective().distance.use_image_prior);
  o.ablation = ClusterSlamAblation::kPointToPointIcp;
  EXPECT_TRUE(o.Effective().motion.point_to_point_icp);
  EXPECT_TRUE(o.distance.use_uncertainty);  // Effective() leaves the original alone
}

TEST(ClusterSlam, OptionsLoadFromYaml) {
  OptionsReader r = OptionsReader::FromString(
      "ablation: no-i\nmax_iterations: 3\nhac: {epsilon: 75}\n"
      "consensus: {chunk_length: 120, min_cluster_size: 5}\ndistance: {alpha: 0.001}\n",
      "test.yaml");
  ClusterSlamOptions o;
  r.LoadInto(&o);
  EXPECT_EQ(o.ablation, ClusterSlamAblation::kNoImagePrior);
  EXPECT_EQ(o.max_iterations, 3);
  EXPECT_EQ(o.hac.epsilon, 75.0);
  EXPECT_EQ(o.consensus.chunk_length, 120);
  EXPECT_EQ(o.consensus.min_cluster_size, 5);
  EXPECT_EQ(o.distance.alpha, 0.001);
  OptionsReader bad = OptionsReader::FromString("ablation: w/o_u\n", "bad.yaml");
  EXPECT_THROW(bad.LoadInto(&o), ConfigError);
  OptionsReader typo = OptionsReader::FromString("hac: {epsilom: 3}\n", "typo.yaml");
  EXPECT_THROW(typo.LoadInto(&o), ConfigError);
  OptionsReader unknown = OptionsReader::FromString("max_iteration: 3\n", "typo.yaml");
  EXPECT_THROW(unknown.LoadInto(&o), ConfigError);
}

// The command line's spelling (`--ablation no-u`) is the only one; the underscore spelling the
// backend section once had is an error listing the allowed words.
TEST(ClusterSlam, AblationIsSpeltWithHyphens) {
  ClusterSlamOptions o;
  OptionsReader hyphen = OptionsReader::FromString("ablation: no-u\n", "t.yaml");
  hyphen.LoadInto(&o);
  EXPECT_EQ(o.ablation, ClusterSlamAblation::kNoUncertainty);
  OptionsReader underscore = OptionsReader::FromString("ablation: no_u\n", "t.yaml");
  try {
    underscore.LoadInto(&o);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "t.yaml:1: ablation: must be one of none, no-u, no-i, p2p-icp, got 'no_u'");
  }
  for (const auto& row : kAblationNames)
    EXPECT_EQ(ParseEnum(kAblationNames, NameOf(kAblationNames, row.value), "ablation"), row.value);
}

TEST(ClusterSlam, CheckRejectsBadValues) {
  ClusterSlamOptions o;
  o.max_iterations = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = ClusterSlamOptions();
  o.consensus.chunk_length = 1;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
