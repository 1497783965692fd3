#include "system/pipeline/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>

#include "core/errors.h"
#include "system/eval/clustering_metrics.h"
#include "system/pipeline/frame_painter.h"
#include "system/synthetic/synthetic_scene.h"
#include "tests/support/matchers.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

RunInput SmallSyntheticInput(double density = 0.3) {
  SyntheticOptions o;
  o.preset = "outdoor";
  o.seed = 3;
  o.frames = 40;
  o.landmark_density = density;
  return SyntheticRunInput(GenerateSynthetic(o));
}

PipelineOptions OnlineOptionsFor(bool sequential) {
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.mode = RunMode::kOnline;
  o.online.sequential = sequential;
  o.backend.max_iterations = 1;  // keeps the test fast; the plumbing is what is pinned here
  return o;
}

TEST(Pipeline, ThreadedOnlineRunEqualsTheSequentialOne) {
  const RunInput in = SmallSyntheticInput();
  const PipelineResult seq = RunPipeline(in, OnlineOptionsFor(true));
  const PipelineResult thr = RunPipeline(in, OnlineOptionsFor(false));
  ASSERT_FALSE(seq.error);
  ASSERT_FALSE(thr.error);
  EXPECT_EQ(seq.frames_processed, 40);
  EXPECT_EQ(thr.frames_processed, 40);
  // Windows end at 30, 35, 40: every frame gets a pose.
  ASSERT_EQ(seq.windows.size(), 3u);
  ASSERT_EQ(thr.windows.size(), 3u);
  ASSERT_EQ(seq.map.num_frames(), 40);
  ASSERT_EQ(thr.map.num_frames(), 40);
  for (int f = 0; f < 40; ++f) {
    ASSERT_TRUE(seq.map.world_from_cam()[f].has_value()) << f;
    ASSERT_TRUE(thr.map.world_from_cam()[f].has_value()) << f;
    EXPECT_TRUE(testing::PoseNear(*seq.map.world_from_cam()[f], *thr.map.world_from_cam()[f],
                                  1e-12, 1e-12));
  }
  // Every observation was replayed; the online run released the frames no window needs any
  // more but kept each landmark's span.
  long long replayed = 0;
  for (int l = 0; l < seq.table.num_landmarks(); ++l) replayed += seq.table.Span(l).observations;
  EXPECT_EQ(replayed, static_cast<long long>(in.observations->num_observations()));
  EXPECT_GT(seq.table.first_held_frame(), 0);
  EXPECT_LT(seq.table.num_observations(), in.observations->num_observations());
}

TEST(Pipeline, KeepingACoreForTheWindowChangesNoResult) {
  // online.reserve_core only moves threads between CPUs (system/runtime/core_reservation.h).
  const RunInput in = SmallSyntheticInput();
  PipelineOptions kept = OnlineOptionsFor(false), shared = OnlineOptionsFor(false);
  kept.online.reserve_core = true;
  shared.online.reserve_core = false;
  const PipelineResult a = RunPipeline(in, kept);
  const PipelineResult b = RunPipeline(in, shared);
  ASSERT_FALSE(a.error);
  ASSERT_FALSE(b.error);
  ASSERT_EQ(a.map.num_frames(), 40);
  ASSERT_EQ(b.map.num_frames(), 40);
  for (int f = 0; f < 40; ++f)
    EXPECT_TRUE(testing::PoseNear(*a.map.world_from_cam()[f], *b.map.world_from_cam()[f], 1e-12,
                                  1e-12))
        << f;
  ASSERT_EQ(a.map.Landmarks(), b.map.Landmarks());
  for (int l : a.map.Landmarks()) EXPECT_EQ(a.map.ClusterOf(l), b.map.ClusterOf(l)) << l;
}

TEST(Pipeline, ForgettingOldObservationsChangesNoResult) {
  const RunInput in = SmallSyntheticInput();
  PipelineOptions keep = OnlineOptionsFor(true);
  keep.online.forget_observations = false;
  const PipelineResult forgot = RunPipeline(in, OnlineOptionsFor(true));
  const PipelineResult kept = RunPipeline(in, keep);
  EXPECT_EQ(kept.table.num_observations(), in.observations->num_observations());
  EXPECT_EQ(kept.table.first_held_frame(), 0);
  EXPECT_GT(forgot.table.first_held_frame(), 0);
  ASSERT_EQ(forgot.map.num_frames(), kept.map.num_frames());
  for (int f = 0; f < kept.map.num_frames(); ++f) {
    ASSERT_EQ(forgot.map.world_from_cam()[f].has_value(), kept.map.world_from_cam()[f].has_value());
    if (kept.map.world_from_cam()[f])
      EXPECT_TRUE(forgot.map.world_from_cam()[f]->matrix() == kept.map.world_from_cam()[f]->matrix()) << f;
  }
  EXPECT_EQ(forgot.map.Landmarks(), kept.map.Landmarks());
  for (int l : kept.map.Landmarks()) EXPECT_EQ(forgot.map.ClusterOf(l), kept.map.ClusterOf(l));
}

// Records what it is asked to paint, from whichever thread calls it.
class RecordingPainter final : public FramePainter {
 public:
  void Paint(const FrameScene& scene, const StereoCamera&, const cv::Mat&, const cv::Mat&,
             const std::string& render_dir) const override {
    const std::lock_guard<std::mutex> lock(mutex_);
    frames_.push_back(scene.frame);
    snapshots_ += scene.snapshot;
    overlays_ += scene.overlay;
    with_points_ += scene.snapshot && !scene.points.empty() && !scene.recent.empty();
    dir_ = render_dir;
  }
  mutable std::mutex mutex_;
  mutable std::vector<int> frames_;
  mutable int snapshots_ = 0, overlays_ = 0, with_points_ = 0;
  mutable std::string dir_;
};

TEST(Pipeline, DueFramesAreHandedToThePainterInOrder) {
  testing::TempDir tmp("pipeline_snapshots");
  for (bool sequential : {false, true}) {
    PipelineOptions o = OnlineOptionsFor(sequential);
    o.output.snapshots_every = 10;
    o.output.overlays_every = 10;  // no images: asked for but nothing to draw on
    o.out_dir = (tmp.path() / (sequential ? "seq" : "thr")).string();
    auto painter = std::make_shared<RecordingPainter>();
    o.painter = painter;
    const PipelineResult r = RunPipeline(SmallSyntheticInput(), o);
    ASSERT_FALSE(r.error);
    EXPECT_EQ(painter->frames_, (std::vector<int>{9, 19, 29, 39})) << sequential;
    EXPECT_EQ(painter->snapshots_, 4);
    EXPECT_EQ(painter->with_points_, 4);
    EXPECT_EQ(painter->overlays_, 0);
    EXPECT_EQ(painter->dir_, (std::filesystem::path(o.out_dir) / "render").string());
    EXPECT_EQ(r.renders.snapshots, 4) << sequential;
    EXPECT_EQ(r.renders.overlays, 0);
    EXPECT_EQ(r.renders.failed, 0);
  }
}

TEST(Pipeline, WithoutAPainterNothingIsDrawn) {
  testing::TempDir tmp("pipeline_no_painter");
  PipelineOptions o = OnlineOptionsFor(true);
  o.output.snapshots_every = 10;
  o.out_dir = tmp.path().string();
  const PipelineResult r = RunPipeline(SmallSyntheticInput(), o);
  ASSERT_FALSE(r.error);
  EXPECT_EQ(r.renders.snapshots, 0);
  EXPECT_EQ(r.renders.failed, 0);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "render" / "snapshot_000009.png"));
}

TEST(Pipeline, ResourcesAreSampledOverTheRun) {
  const PipelineResult r = RunPipeline(SmallSyntheticInput(), OnlineOptionsFor(true));
  ASSERT_GE(r.resources.size(), 2u);
  EXPECT_EQ(r.resources.back().frame, r.frames_processed);
  for (size_t i = 1; i < r.resources.size(); ++i) {
    EXPECT_GT(r.resources[i].frame, r.resources[i - 1].frame);
    EXPECT_GE(r.resources[i].elapsed_s, r.resources[i - 1].elapsed_s);
  }
  EXPECT_GT(r.resources.back().rss_mb, 1.0);  // this process holds at least a few MiB
}

TEST(Pipeline, AStopRequestBeforeTheFirstFrameEndsWithNothingProcessed) {
  const RunInput in = SmallSyntheticInput();
  std::atomic<bool> stop{true};
  for (bool sequential : {true, false}) {
    const PipelineResult r = RunPipeline(in, OnlineOptionsFor(sequential), &stop);
    EXPECT_TRUE(r.interrupted);
    EXPECT_EQ(r.frames_processed, 0);
    EXPECT_TRUE(r.windows.empty());
  }
}

TEST(Pipeline, BatchModeGivesEveryFrameAPoseNearTheTruth) {
  // Without the image prior the static background stays one cluster on this scene (with the
  // paper's α it splits: docs/experiments/2026-11-23-backend-with-model-assignment.md), so
  // the camera is solved against the world.
  // The cold loop on purpose: the online windows, and so the warm start built on them, take
  // this scene's cars for the static world (measured: the warm camera error is tens of metres).
  const RunInput in = SmallSyntheticInput(1.0);
  PipelineOptions o = OnlineOptionsFor(true);
  o.mode = RunMode::kBatch;
  o.batch.warm_start = false;
  o.backend.max_iterations = 5;
  o.ApplyAblation(ClusterSlamAblation::kNoImagePrior);
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_EQ(r.windows.size(), 1u);
  ASSERT_TRUE(r.batch.has_value());
  ASSERT_EQ(r.map.num_frames(), 40);
  // The first camera defines the world: the estimate and the truth share their origin.
  double max_err = 0;
  for (int f = 0; f < 40; ++f)
    max_err = std::max(max_err, ((*r.map.world_from_cam()[f]).translation() -
                                 (*in.gt_world_from_cam)[f].translation()).norm());
  EXPECT_LT(max_err, 0.5);
}

double BatchAccuracy(const RunInput& in, const PipelineResult& r) {
  std::vector<int> truth, predicted;
  const std::vector<int>& labels = r.batch->estimate.landmark_cluster;
  for (int l : in.observations->LandmarksIn({0, in.observations->num_frames()}, 4)) {
    truth.push_back(in.synthetic->landmark_object[l]);
    predicted.push_back(l < static_cast<int>(labels.size()) ? labels[l] : -1);
  }
  return ClusteringAccuracy(truth, predicted);
}

double CameraRms(const RunInput& in, const PipelineResult& r) {
  double sum = 0.0;
  for (int f = 0; f < r.map.num_frames(); ++f)
    sum += ((*r.map.world_from_cam()[f]).translation() - (*in.gt_world_from_cam)[f].translation())
               .squaredNorm();
  return std::sqrt(sum / r.map.num_frames());
}

// The "true-labels" reference: the generator's labels, ClusterSLAM's estimation. It must keep
// the labels it is given (accuracy 1) and, with the cars separated, beat Full BA's camera.
TEST(Pipeline, TrueLabelsMethodKeepsTheGeneratorsLabelsAndBeatsFullBa) {
  const RunInput in = SmallSyntheticInput(1.0);
  PipelineOptions o = OnlineOptionsFor(true);
  o.mode = RunMode::kBatch;
  o.method = Method::kTrueLabels;
  const PipelineResult truth = RunPipeline(in, o);
  o.method = Method::kFullBa;
  const PipelineResult full = RunPipeline(in, o);
  ASSERT_TRUE(truth.batch.has_value());
  ASSERT_TRUE(full.batch.has_value());
  EXPECT_EQ(truth.batch->method, "true-labels");
  EXPECT_DOUBLE_EQ(BatchAccuracy(in, truth), 1.0);
  const double rms = CameraRms(in, truth), rms_full = CameraRms(in, full);
  std::printf("camera RMS: true labels %.4f m, full BA %.4f m\n", rms, rms_full);
  EXPECT_LT(rms, 0.5 * rms_full);
}

TEST(Pipeline, TrueLabelsMethodNeedsReplayedSyntheticTracklets) {
  RunInput in;
  in.path = "/data/clip_a";
  in.kind = InputKind::kKittiOdometry;
  PipelineOptions o;
  o.method = Method::kTrueLabels;
  try {
    RunPipeline(in, o);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/data/clip_a is a kitti_odometry sequence"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(CheckMethodFitsInput(Method::kFullBa, in));
  EXPECT_NO_THROW(CheckMethodFitsInput(Method::kTrueLabels, SmallSyntheticInput()));
}

// batch.warm_start (the default): the whole-sequence call starts from the online windows' map;
// it must be one warm-started call that clusters and places the camera as well as the cold one.
TEST(Pipeline, WarmStartedBatchClustersAsWellAsTheColdOne) {
  SyntheticOptions so;
  so.preset = "outdoor";
  so.seed = 1;
  so.frames = 60;
  const RunInput in = SyntheticRunInput(GenerateSynthetic(so));
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.mode = RunMode::kBatch;
  const PipelineResult warm = RunPipeline(in, o);
  o.batch.warm_start = false;
  const PipelineResult cold = RunPipeline(in, o);
  ASSERT_TRUE(cold.batch.has_value());
  ASSERT_TRUE(warm.batch.has_value());
  EXPECT_FALSE(cold.batch->warm_started);
  EXPECT_TRUE(warm.batch->warm_started);
  ASSERT_EQ(warm.windows.size(), 1u);
  const double acc_cold = BatchAccuracy(in, cold), acc_warm = BatchAccuracy(in, warm);
  std::printf("accuracy cold %.4f warm %.4f\n", acc_cold, acc_warm);
  EXPECT_GE(acc_warm, acc_cold - 0.01);
  EXPECT_GE(acc_warm, 0.9);  // measured: cold 0.930, warm 0.931
  double max_err = 0;
  for (int f = 0; f < in.observations->num_frames(); ++f)
    max_err = std::max(max_err, ((*warm.map.world_from_cam()[f]).translation() -
                                 (*in.gt_world_from_cam)[f].translation()).norm());
  std::printf("warm max camera error %.4f m\n", max_err);
  EXPECT_LT(max_err, 0.1);  // measured 0.022 m
}

// A whole generated outdoor drive, replayed at the landmark level.
RunInput OutdoorDrive(int seed) {
  SyntheticOptions so;
  so.preset = "outdoor";
  so.seed = seed;
  return SyntheticRunInput(GenerateSynthetic(so));
}

// Reported object (cluster id) → true object → its landmarks there.
using ObjectVotes = std::map<int, std::map<int, int>>;
ObjectVotes VotesOfReportedObjects(const RunInput& in, const PipelineResult& r) {
  ObjectVotes votes;
  for (int l = 0; l < static_cast<int>(in.synthetic->landmark_object.size()); ++l) {
    const int c = r.map.ClusterOf(l);
    if (r.object_tracks.count(c)) ++votes[c][in.synthetic->landmark_object[l]];
  }
  return votes;
}

// The true object holding most of a reported object's landmarks.
std::pair<int, int> MajorityOf(const std::map<int, int>& by_car) {
  return *std::max_element(by_car.begin(), by_car.end(),
                           [](const auto& a, const auto& b) { return a.second < b.second; });
}

// The whole-sequence solve of a far car (30–45 m, ~40 poses) takes hundreds of small LM
// steps; stopped half-way, it judges half of the car's landmarks as not fitting, and the
// outlier re-clustering makes a second object of the same car (outdoor seed 2 at a 50-step
// cap: 4 cars in two objects; docs/experiments/2026-12-07-batch-solves-run-to-convergence.md).
// The split by place is off here: it takes 17 of car 8's landmarks out of car 1's object as a
// piece of their own that nothing joins to car 8's object (no shared frame), a second object
// of another cause (docs/experiments/2026-12-07-one-motion-two-places.md).
TEST(Pipeline, WarmBatchReportsEachFarCarOfAnOutdoorDriveOnce) {
  const RunInput in = OutdoorDrive(2);
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.mode = RunMode::kBatch;
  o.output.trajectory_plot = false;
  o.backend.assignment.split_gap_m = 0;
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_FALSE(r.error);
  // Each reported object's majority true car; a car that is the majority of two is split.
  const ObjectVotes votes = VotesOfReportedObjects(in, r);
  std::map<int, int> objects_per_car;
  for (const auto& [c, by_car] : votes)
    if (const int car = MajorityOf(by_car).first; car > 0) ++objects_per_car[car];
  std::printf("%zu reported objects on %zu cars\n", votes.size(), objects_per_car.size());
  EXPECT_GE(objects_per_car.size(), 8u);  // measured: 10 of its 10 cars
  for (const auto& [car, n] : objects_per_car) EXPECT_EQ(n, 1) << "car " << car;
}

// Outdoor seed 1's cars 6 and 9 cross in opposite directions 30–40 m away: over a window's
// few shared frames one rigid motion explains both within the depth noise, and before the
// split by place (backend.assignment.split_gap_m) one object held both (50 + 30 landmarks,
// 21 m object ATE). Their landmarks are metres apart: two objects.
TEST(Pipeline, TwoCarsOfOneMotionInTwoPlacesAreTwoObjectsOnline) {
  const RunInput in = OutdoorDrive(1);
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.mode = RunMode::kOnline;
  o.online.sequential = true;
  o.output.trajectory_plot = false;
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_FALSE(r.error);
  ObjectVotes votes = VotesOfReportedObjects(in, r);
  std::map<int, int> object_of_car;  // true car -> the reported object it is the majority of
  for (const auto& [c, by_car] : votes) {
    const auto [car, landmarks] = MajorityOf(by_car);
    std::printf("object %d: car %d with %d landmarks\n", c, car, landmarks);
    object_of_car[car] = c;
  }
  ASSERT_TRUE(object_of_car.count(6)) << "car 6 is no object's majority";
  ASSERT_TRUE(object_of_car.count(9)) << "car 9 is no object's majority";
  EXPECT_NE(object_of_car[6], object_of_car[9]);
  EXPECT_LT(votes[object_of_car[9]][6], 5);  // measured: 0 (30 before the split)
}

// Outdoor seed 3's car 3 (30 m ahead) moves along the line of sight: a warm window's first
// assignment, with only the static model, finds its landmarks one static point each about as
// well, and window after window gave them to the static world. The outdoor preset keeps a
// moving landmark in its cluster across windows (favour_own_label + keep_moving_labels), and
// the end of the run joins the pieces that leaves: no car is two objects.
ObjectVotes OnlineObjectVotes(int seed, bool sticky) {
  const RunInput in = OutdoorDrive(seed);
  PipelineOptions o;
  o.ApplyPreset(Preset::kOutdoor);
  o.backend.assignment.favour_own_label = sticky;
  o.backend.window_prior.keep_moving_labels = sticky;
  o.mode = RunMode::kOnline;
  o.online.sequential = true;
  o.output.trajectory_plot = false;
  const PipelineResult r = RunPipeline(in, o);
  EXPECT_FALSE(r.error);
  return VotesOfReportedObjects(in, r);
}

int LandmarksOfCarInObjects(const ObjectVotes& votes, int car) {
  int n = 0;
  for (const auto& [c, by_car] : votes)
    if (const auto it = by_car.find(car); it != by_car.end()) n += it->second;
  return n;
}

TEST(Pipeline, OnlineOutdoorRunsKeepAFarCarAlongTheLineOfSightAcrossWindows) {
  const ObjectVotes sticky = OnlineObjectVotes(3, true), not_sticky = OnlineObjectVotes(3, false);
  const int kept = LandmarksOfCarInObjects(sticky, 3), lost = LandmarksOfCarInObjects(not_sticky, 3);
  std::printf("car 3's landmarks in objects: %d kept across windows, %d not\n", kept, lost);
  EXPECT_GE(kept, 2 * lost);  // measured: 33 against 13
  std::map<int, int> objects;  // true car -> reported objects it is the majority of
  for (const auto& [c, by_car] : sticky) ++objects[MajorityOf(by_car).first];
  for (const auto& [car, n] : objects)
    if (car > 0) EXPECT_EQ(n, 1) << "car " << car;
  EXPECT_EQ(objects[3], 1);
}

// batch.native_sparse_solver reaches the whole-sequence call only: the online windows of the
// warm start keep the backend's own solver choice.
TEST(Pipeline, WarmBatchPutsOnlyTheWholeSequenceOnTheNativeSparseSolver) {
  const RunInput in = SmallSyntheticInput();
  struct Call {
    FrameRange range;
    bool native_sparse = false;
    bool has_prior = false;
  };
  for (bool native : {true, false}) {
    PipelineOptions o = OnlineOptionsFor(true);
    o.mode = RunMode::kBatch;
    o.batch.native_sparse_solver = native;
    std::vector<Call> calls;
    const BackendFunction recording = [&calls](const TrackletTable& t, const StereoCamera& c,
                                               FrameRange r, const PipelineOptions& opts,
                                               const WindowPrior* prior) {
      calls.push_back({r, opts.backend.motion.bundle_adjustment.native_sparse_solver, prior != nullptr});
      return RunBackend(t, c, r, opts, prior);
    };
    const PipelineResult r = RunPipeline(in, o, nullptr, {}, recording);
    ASSERT_FALSE(r.error);
    ASSERT_EQ(calls.size(), 4u);  // online windows ending at 30, 35, 40, then the whole sequence
    for (size_t k = 0; k + 1 < calls.size(); ++k) {
      EXPECT_EQ(calls[k].range.size(), o.online.window_frames) << k;
      EXPECT_FALSE(calls[k].native_sparse) << k;  // the backend's default
    }
    EXPECT_EQ(calls.back().range, (FrameRange{0, 40}));
    EXPECT_TRUE(calls.back().has_prior);
    EXPECT_EQ(calls.back().native_sparse, native);
  }
}

// The accuracy of warm-started windows against cold ones is pinned on ground truth in
// window_prior_test.cc (a stretch where a cold window clusters well; this small scene is not
// one); here the plumbing: which windows start from the map, and determinism.
TEST(Pipeline, OnlineWindowsAfterTheFirstStartFromTheMapDeterministically) {
  const RunInput in = SmallSyntheticInput();
  PipelineOptions warm = OnlineOptionsFor(true);
  PipelineOptions cold = warm;
  cold.backend.window_prior.enabled = false;
  const PipelineResult w = RunPipeline(in, warm);
  const PipelineResult c = RunPipeline(in, cold);
  ASSERT_EQ(w.windows.size(), 3u);
  ASSERT_EQ(c.windows.size(), 3u);
  EXPECT_FALSE(w.windows[0].warm_started);  // nothing in the map yet
  EXPECT_TRUE(w.windows[1].warm_started);
  EXPECT_TRUE(w.windows[2].warm_started);
  for (const WindowStats& s : c.windows) EXPECT_FALSE(s.warm_started);
  ASSERT_EQ(w.map.num_frames(), 40);
  const PipelineResult again = RunPipeline(in, warm);
  ASSERT_EQ(again.map.num_frames(), 40);
  for (int f = 0; f < 40; ++f)
    EXPECT_TRUE(testing::PoseNear(*w.map.world_from_cam()[f], *again.map.world_from_cam()[f], 1e-12, 1e-12));
  EXPECT_EQ(w.map.Landmarks(), again.map.Landmarks());
  for (int l : w.map.Landmarks()) EXPECT_EQ(w.map.ClusterOf(l), again.map.ClusterOf(l)) << l;
}

// A backend that fails (throws, or returns non-finite poses) for the windows ending at the
// given frames and runs the real one otherwise.
BackendFunction FailingAt(std::vector<int> throw_at, std::vector<int> nan_at) {
  return [=](const TrackletTable& t, const StereoCamera& c, FrameRange r, const PipelineOptions& o,
             const WindowPrior* prior) {
    if (std::find(throw_at.begin(), throw_at.end(), r.end) != throw_at.end())
      throw std::runtime_error("injected solver failure");
    BackendResult b = RunBackend(t, c, r, o, prior);
    if (std::find(nan_at.begin(), nan_at.end(), r.end) != nan_at.end())
      b.estimate.world_from_cam[1].translation().x() = std::numeric_limits<double>::quiet_NaN();
    return b;
  };
}

// A window's cost must follow what it holds, not how many landmarks the run has made.
TEST(Pipeline, EachOnlineWindowHandsTheBackendOnlyItsOwnLandmarks) {
  const RunInput in = SmallSyntheticInput();
  for (bool sequential : {true, false}) {
    std::mutex mutex;
    std::vector<std::pair<int, int>> sizes;  // (landmarks in the table, landmarks seen in range)
    const BackendFunction recording = [&](const TrackletTable& t, const StereoCamera& c,
                                          FrameRange r, const PipelineOptions& o,
                                          const WindowPrior* prior) {
      {
        const std::lock_guard<std::mutex> lock(mutex);
        sizes.emplace_back(t.num_landmarks(), static_cast<int>(t.LandmarksIn(r).size()));
      }
      return RunBackend(t, c, r, o, prior);
    };
    const PipelineResult out = RunPipeline(in, OnlineOptionsFor(sequential), nullptr, {}, recording);
    ASSERT_FALSE(out.error);
    ASSERT_EQ(sizes.size(), 3u);
    for (const auto& [held, seen] : sizes) EXPECT_EQ(held, seen);
    EXPECT_LT(sizes.back().first, out.table.num_landmarks());  // frames 10..39 of 0..39
  }
}

TEST(Pipeline, AFailedWindowIsDiscardedAndTheRunGoesOn) {
  const RunInput in = SmallSyntheticInput();
  for (bool sequential : {true, false}) {
    // Windows end at 30, 35, 40: the second throws, a NaN spoils the third in a second run.
    const PipelineResult thrown = RunPipeline(in, OnlineOptionsFor(sequential), nullptr, {}, FailingAt({35}, {}));
    ASSERT_FALSE(thrown.error);
    EXPECT_EQ(thrown.frames_processed, 40);
    ASSERT_EQ(thrown.windows.size(), 3u);
    EXPECT_FALSE(thrown.windows[0].failed);
    EXPECT_TRUE(thrown.windows[1].failed);
    EXPECT_FALSE(thrown.windows[2].failed);
    // The window after the failure still covers every frame.
    for (int f = 0; f < 40; ++f) EXPECT_TRUE(thrown.map.world_from_cam()[f].has_value()) << f;

    const PipelineResult nan = RunPipeline(in, OnlineOptionsFor(sequential), nullptr, {}, FailingAt({}, {40}));
    ASSERT_FALSE(nan.error);
    ASSERT_EQ(nan.windows.size(), 3u);
    EXPECT_TRUE(nan.windows[2].failed);
    // Frames 35..39 only the failed window covered: no pose rather than a NaN one.
    for (int f = 0; f < 35; ++f) EXPECT_TRUE(nan.map.world_from_cam()[f].has_value()) << f;
    for (int f = 0; f < nan.map.num_frames(); ++f) {
      if (nan.map.world_from_cam()[f]) {
        EXPECT_TRUE(nan.map.world_from_cam()[f]->matrix().allFinite()) << f;
      }
    }
  }
}

TEST(Pipeline, AFiniteButAbsurdEstimateIsDiscarded) {
  // The old check (every pose finite) let a diverged solve through: camera steps of 1e20 m.
  const RunInput in = SmallSyntheticInput();
  const BackendFunction jumping = [](const TrackletTable& t, const StereoCamera& c, FrameRange r,
                                     const PipelineOptions& o, const WindowPrior* prior) {
    BackendResult b = RunBackend(t, c, r, o, prior);
    if (r.end == 40)
      for (size_t f = 5; f < b.estimate.world_from_cam.size(); ++f)
        b.estimate.world_from_cam[f].translation().z() += 1e20;
    return b;
  };
  const PipelineResult r = RunPipeline(in, OnlineOptionsFor(true), nullptr, {}, jumping);
  ASSERT_FALSE(r.error);
  ASSERT_EQ(r.windows.size(), 3u);
  EXPECT_FALSE(r.windows[0].failed);
  EXPECT_FALSE(r.windows[1].failed);
  EXPECT_TRUE(r.windows[2].failed);
  for (int f = 0; f < r.map.num_frames(); ++f)
    if (r.map.world_from_cam()[f]) EXPECT_LT(r.map.world_from_cam()[f]->translation().norm(), 1e3) << f;
}

TEST(Pipeline, AFailedBatchCallLeavesAnEmptyMapNotAnError) {
  const RunInput in = SmallSyntheticInput();
  PipelineOptions o = OnlineOptionsFor(true);
  o.mode = RunMode::kBatch;
  const PipelineResult r = RunPipeline(in, o, nullptr, {}, FailingAt({40}, {}));
  ASSERT_FALSE(r.error);
  ASSERT_EQ(r.windows.size(), 1u);
  EXPECT_TRUE(r.windows[0].failed);
  for (const auto& p : r.map.world_from_cam()) EXPECT_FALSE(p.has_value());
}

// `in` with frames [from, to) emptied (black frames: the frontend sees nothing) and every
// landmark seen on both sides split in two, as a frontend that lost its tracks would see it.
RunInput WithTrackingLoss(const RunInput& in, int from, int to) {
  RunInput out;
  out.name = in.name;
  out.kind = in.kind;
  out.camera = in.camera;
  out.timestamps = in.timestamps;
  out.gt_world_from_cam = in.gt_world_from_cam;
  TrackletTable t;
  const TrackletTable& given = *in.observations;
  const int n = given.num_landmarks();
  for (int l = 0; l < n; ++l)
    for (const StereoObservation& o : given.ObservationsOf(l)) {
      if (o.frame >= from && o.frame < to) continue;
      t.Add(o.frame >= to ? l + n : l, o.frame, o.x, o.cov);
    }
  out.observations = std::move(t);
  return out;
}

TEST(Pipeline, NoWindowSpansATrackingLossAndTheMapMarksTheGap) {
  const RunInput in = WithTrackingLoss(SmallSyntheticInput(), 18, 20);
  for (bool sequential : {true, false}) {
    const PipelineResult r = RunPipeline(in, OnlineOptionsFor(sequential));
    ASSERT_FALSE(r.error);
    EXPECT_EQ(r.frames_processed, 40);
    ASSERT_FALSE(r.windows.empty());
    for (const WindowStats& w : r.windows) {
      EXPECT_FALSE(w.failed) << w.range.begin << ".." << w.range.end;
      EXPECT_FALSE(w.range.Contains(18) || w.range.Contains(19)) << w.range.begin << ".." << w.range.end;
      EXPECT_FALSE(w.range.Contains(17) && w.range.Contains(20)) << w.range.begin << ".." << w.range.end;
    }
    // Before the loss, in the dark, after it.
    for (int f = 0; f < 18; ++f) EXPECT_TRUE(r.map.world_from_cam()[f].has_value()) << f;
    EXPECT_FALSE(r.map.world_from_cam()[18].has_value());
    EXPECT_FALSE(r.map.world_from_cam()[19].has_value());
    for (int f = 20; f < 40; ++f) EXPECT_TRUE(r.map.world_from_cam()[f].has_value()) << f;
    ASSERT_EQ(r.map.gaps().size(), 1u);
    EXPECT_EQ(r.map.gaps()[0], 20);
  }
}

TEST(Pipeline, BatchModeSolvesEachStretchBetweenTrackingLosses) {
  const RunInput in = WithTrackingLoss(SmallSyntheticInput(), 18, 20);
  PipelineOptions o = OnlineOptionsFor(true);
  o.mode = RunMode::kBatch;
  const PipelineResult r = RunPipeline(in, o);
  ASSERT_FALSE(r.error);
  ASSERT_EQ(r.windows.size(), 2u);
  EXPECT_EQ(r.windows[0].range, (FrameRange{0, 18}));
  EXPECT_EQ(r.windows[1].range, (FrameRange{20, 40}));
  EXPECT_FALSE(r.map.world_from_cam()[19].has_value());
  EXPECT_TRUE(r.map.world_from_cam()[39].has_value());
  ASSERT_EQ(r.map.gaps().size(), 1u);
}

}  // namespace
}  // namespace cslam
