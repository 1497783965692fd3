// The online warm start on the generator's ground truth: a window started from the map that an
// earlier (cold) window left behind labels and places the window as well as a cold start does,
// corrects wrong labels in the prior, and falls back to the cold start when the prior is not
// usable.
#include "system/map/window_prior.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "backend/clusterslam.h"
#include "core/errors.h"
#include "system/eval/clustering_metrics.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {
namespace {

// Outdoor seed 1 from frame 100: a stretch where a cold 30-frame window clusters well
// (measured accuracy 0.90, camera 0.014 m RMS; from frame 20, three cars driving along with
// the camera hold more observations than the street and a cold window takes them for the
// static world).
constexpr FrameRange kFirst{100, 130};   // the window the map comes from
constexpr FrameRange kWindow{105, 135};  // the next window, 5 frames later

struct Fixture {
  SyntheticSequence seq;
  TrackletTable table;  // observations of kWindow only, as the pipeline hands them over
  MapState map;
  BackendResult cold;   // RunClusterSlam on kWindow
};

const Fixture& Outdoor() {
  static const Fixture f = [] {
    Fixture x;
    SyntheticOptions o;
    o.preset = "outdoor";
    o.seed = 1;
    o.frames = 140;
    x.seq = GenerateSynthetic(o);
    const ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
    x.map.Integrate(RunClusterSlam(x.seq.observations.Slice(kFirst), x.seq.camera, kFirst, options).estimate);
    x.table = x.seq.observations.Slice(kWindow);
    x.cold = RunClusterSlam(x.table, x.seq.camera, kWindow, options);
    return x;
  }();
  return f;
}

double Accuracy(const Fixture& f, const std::vector<int>& labels) {
  std::vector<int> truth, predicted;
  for (int l : f.table.LandmarksIn(kWindow, 4)) {
    truth.push_back(f.seq.landmark_object[l]);
    predicted.push_back(l < static_cast<int>(labels.size()) ? labels[l] : -1);
  }
  return ClusteringAccuracy(truth, predicted);
}

// RMS camera position error in the window's frame (world = the camera at kWindow.begin).
double CameraRms(const Fixture& f, const MotionEstimate& est) {
  const Pose window_from_world = f.seq.world_from_cam[kWindow.begin].inverse();
  double sum = 0;
  for (int k = 0; k < kWindow.size(); ++k) {
    const Pose truth = window_from_world * f.seq.world_from_cam[kWindow.begin + k];
    sum += (est.world_from_cam[k].translation() - truth.translation()).squaredNorm();
  }
  return std::sqrt(sum / kWindow.size());
}

TEST(WindowPriorFromMap, HoldsTheMapsPosesLabelsAndStaticPositionsInTheWindowFrame) {
  const Fixture& f = Outdoor();
  const std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  EXPECT_EQ(prior->range, kWindow);
  // The map has frames 100..129: 25 of the window's 30.
  EXPECT_EQ(prior->KnownFrames(), 25);
  for (int k = 0; k < 25; ++k) ASSERT_TRUE(prior->world_from_cam[k]) << k;
  EXPECT_TRUE(prior->world_from_cam[0]->isApprox(Pose::Identity()));
  const Pose map_from_window = *f.map.world_from_cam()[kWindow.begin];
  for (int k = 0; k < 25; ++k)
    EXPECT_TRUE((map_from_window * *prior->world_from_cam[k]).isApprox(*f.map.world_from_cam()[kWindow.begin + k], 1e-9));
  int known = 0, unknown = 0;
  for (int l : f.table.LandmarksIn(kWindow)) {
    EXPECT_EQ(prior->ClusterOf(l), f.map.ClusterOf(l)) << l;
    (prior->ClusterOf(l) >= 0 ? known : unknown)++;
    if (prior->ClusterOf(l) == 0)
      EXPECT_LT((map_from_window * prior->static_point[l] - *f.map.PositionInCluster(l)).norm(), 1e-9);
    else
      EXPECT_FALSE(prior->static_point[l].allFinite());
  }
  EXPECT_GT(known, 0);
  EXPECT_GT(unknown, 0) << "the window's last frames should bring landmarks new to the map";
}

TEST(WindowPriorFromMap, NothingWithoutACameraPoseAtTheWindowStart) {
  const Fixture& f = Outdoor();
  EXPECT_FALSE(WindowPriorFromMap(MapState{}, f.table, kWindow));
  // The map starts at frame 100: a window from frame 90 has no pose at its first frame.
  EXPECT_FALSE(WindowPriorFromMap(f.map, f.seq.observations.Slice({90, 120}), {90, 120}));
}

TEST(WarmStart, GivesTheColdStartsLabelsAndCameraWithFewerIterations) {
  const Fixture& f = Outdoor();
  const std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  for (bool keep : {false, true}) {
    SCOPED_TRACE(keep ? "moving labels kept" : "static labels only");
    ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
    options.window_prior.keep_moving_labels = keep;
    const BackendResult warm = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, options, &*prior);
    ASSERT_TRUE(warm.warm_started);
    EXPECT_FALSE(f.cold.warm_started);
    const double warm_accuracy = Accuracy(f, warm.estimate.landmark_cluster);
    const double cold_accuracy = Accuracy(f, f.cold.estimate.landmark_cluster);
    // Measured: warm 0.866 (moving labels kept: 0.863), cold 0.866, labellings 0.94 (0.91)
    // alike (before the split by place, backend.assignment.split_gap_m: 0.880 / 0.907 / 0.880,
    // 0.99 / 0.98); camera 0.023 m / 0.019 m RMS.
    EXPECT_GE(warm_accuracy, 0.85);
    EXPECT_GE(warm_accuracy, cold_accuracy - 0.02) << "cold " << cold_accuracy;
    // The two agree with each other about as well as with the truth.
    std::vector<int> a, b;
    for (int l : f.table.LandmarksIn(kWindow, 4)) {
      a.push_back(warm.estimate.landmark_cluster[l]);
      b.push_back(f.cold.estimate.landmark_cluster[l]);
    }
    std::printf("%s: warm %.3f cold %.3f, alike %.3f\n", keep ? "moving labels kept" : "static labels only",
                warm_accuracy, cold_accuracy, ClusteringAccuracy(b, a));
    EXPECT_GE(ClusteringAccuracy(b, a), 0.9);
    const double warm_rms = CameraRms(f, warm.estimate);
    const double cold_rms = CameraRms(f, f.cold.estimate);
    EXPECT_LT(warm_rms, std::max(1.5 * cold_rms, cold_rms + 0.02)) << "cold " << cold_rms << " m";
    EXPECT_LE(warm.iterations.size(), 1u + options.window_prior.max_iterations);
  }
}

// fix_known_poses (free_known_frames 0): the 25 frames the map has keep the map's poses
// exactly, and within one window holding them costs nothing in accuracy against the
// generator's truth — the labels and the camera (including the 5 new frames) are as good as
// with every pose adjusted. (Over a whole run the held poses drift more outdoors, which is why
// the option is off by default: docs/experiments/2026-12-01-faster-warm-windows.md.)
TEST(WarmStart, KnownPosesHeldFixedStayTheMapsAndKeepTheAccuracy) {
  const Fixture& f = Outdoor();
  const std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
  options.window_prior.fix_known_poses = true;
  options.window_prior.free_known_frames = 0;
  const BackendResult held = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, options, &*prior);
  options.window_prior.fix_known_poses = false;
  const BackendResult free = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, options, &*prior);
  ASSERT_TRUE(held.warm_started);
  ASSERT_TRUE(free.warm_started);
  int moved = 0;
  for (int k = 0; k < kWindow.size(); ++k) {
    if (!prior->world_from_cam[k]) continue;
    EXPECT_TRUE(held.estimate.world_from_cam[k].matrix() == prior->world_from_cam[k]->matrix()) << k;
    moved += !free.estimate.world_from_cam[k].isApprox(*prior->world_from_cam[k], 1e-9);
  }
  EXPECT_GT(moved, 0) << "the free adjustment should move the map's poses";
  // New frames only: RMS camera position error over the 5 frames the map lacks.
  auto new_frames_rms = [&](const MotionEstimate& est) {
    const Pose window_from_world = f.seq.world_from_cam[kWindow.begin].inverse();
    double sum = 0;
    int count = 0;
    for (int k = 0; k < kWindow.size(); ++k) {
      if (prior->world_from_cam[k]) continue;
      const Pose truth = window_from_world * f.seq.world_from_cam[kWindow.begin + k];
      sum += (est.world_from_cam[k].translation() - truth.translation()).squaredNorm();
      ++count;
    }
    return std::sqrt(sum / count);
  };
  const double held_accuracy = Accuracy(f, held.estimate.landmark_cluster);
  const double free_accuracy = Accuracy(f, free.estimate.landmark_cluster);
  std::printf("held: accuracy %.3f, camera %.4f m (new frames %.4f m); free: %.3f, %.4f m (%.4f m)\n",
              held_accuracy, CameraRms(f, held.estimate), new_frames_rms(held.estimate),
              free_accuracy, CameraRms(f, free.estimate), new_frames_rms(free.estimate));
  EXPECT_GE(held_accuracy, 0.85);
  EXPECT_GE(held_accuracy, free_accuracy - 0.02);
  EXPECT_LT(CameraRms(f, held.estimate), CameraRms(f, free.estimate) + 0.01);
  EXPECT_LT(new_frames_rms(held.estimate), new_frames_rms(free.estimate) + 0.01);
}

// free_known_frames: the newest known poses are adjusted, the older ones held.
TEST(WarmStart, TheNewestKnownPosesStayFree) {
  const Fixture& f = Outdoor();
  const std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
  options.window_prior.fix_known_poses = true;
  options.window_prior.free_known_frames = 10;
  const BackendResult warm = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, options, &*prior);
  ASSERT_TRUE(warm.warm_started);
  int moved = 0;
  for (int k = 0; k < 25; ++k) {
    ASSERT_TRUE(prior->world_from_cam[k]);
    const bool same = warm.estimate.world_from_cam[k].matrix() == prior->world_from_cam[k]->matrix();
    if (k < 15) EXPECT_TRUE(same) << k;
    moved += !same;
  }
  EXPECT_GE(moved, 5) << "frames 15..24 are free";
}

TEST(WarmStart, WrongLabelsInThePriorAreCorrected) {
  const Fixture& f = Outdoor();
  std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  // Every fifth truly static landmark the map calls static is put into a moving map cluster
  // of its own (as if an earlier window had split it off), every fifth but one into a real
  // moving cluster of the map.
  ASSERT_FALSE(f.map.clusters().empty());
  const int car = f.map.clusters().begin()->first;
  std::vector<int> corrupted;
  int k = 0;
  for (int l : f.table.LandmarksIn(kWindow, 8)) {
    if (prior->ClusterOf(l) != 0 || f.seq.landmark_object[l] != 0) continue;
    if (k % 5 == 0) prior->landmark_cluster[l] = 9999;
    if (k % 5 == 1) prior->landmark_cluster[l] = car;
    if (k % 5 <= 1) corrupted.push_back(l);
    ++k;
  }
  ASSERT_GE(corrupted.size(), 50u);
  for (bool keep : {false, true}) {
    SCOPED_TRACE(keep ? "moving labels kept" : "static labels only");
    ClusterSlamOptions options = ClusterSlamOptions::Outdoor();
    options.window_prior.keep_moving_labels = keep;
    const BackendResult warm = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, options, &*prior);
    ASSERT_TRUE(warm.warm_started);
    int fixed = 0;
    for (int l : corrupted) fixed += warm.estimate.landmark_cluster[l] == 0;
    EXPECT_GE(fixed, 0.9 * corrupted.size()) << fixed << " of " << corrupted.size();
    EXPECT_GE(Accuracy(f, warm.estimate.landmark_cluster),
              Accuracy(f, f.cold.estimate.landmark_cluster) - 0.02);
  }
}

TEST(WarmStart, AnUnusablePriorOrTheSwitchGivesTheColdStart) {
  const Fixture& f = Outdoor();
  std::optional<WindowPrior> prior = WindowPriorFromMap(f.map, f.table, kWindow);
  ASSERT_TRUE(prior);
  ClusterSlamOptions off = ClusterSlamOptions::Outdoor();
  off.window_prior.enabled = false;
  const BackendResult switched = RunClusterSlamWindow(f.table, f.seq.camera, kWindow, off, &*prior);
  EXPECT_FALSE(switched.warm_started);
  EXPECT_EQ(switched.estimate.landmark_cluster, f.cold.estimate.landmark_cluster);

  // Only the first frames posed: below min_known_frames.
  for (int k = 5; k < kWindow.size(); ++k) prior->world_from_cam[k].reset();
  std::string why;
  EXPECT_FALSE(PriorIsUsable(*prior, f.table, kWindow, WindowPriorOptions{}, &why));
  EXPECT_NE(why.find("5 of 30 frames"), std::string::npos) << why;
  const BackendResult refused =
      RunClusterSlamWindow(f.table, f.seq.camera, kWindow, ClusterSlamOptions::Outdoor(), &*prior);
  EXPECT_FALSE(refused.warm_started);
  EXPECT_EQ(refused.estimate.landmark_cluster, f.cold.estimate.landmark_cluster);
}

TEST(WarmStart, OptionsAreChecked) {
  WindowPriorOptions o;
  EXPECT_NO_THROW(o.Check());
  o.ba_iterations = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.min_known_frames = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.max_iterations = 0;
  try {
    o.Check();
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "max_iterations") << e.what();
  }
}

}  // namespace
}  // namespace cslam
