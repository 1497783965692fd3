#include "system/pipeline.h"

#include <gtest/gtest.h>

#include "system/synthetic_scene.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

RunInput SmallSyntheticInput(double density = 0.3) {
  SyntheticOptions o;
  o.preset = "outdoor";
  o.seed = 3;
  o.frames = 40;
  o.landmark_density = density;
  SyntheticSequence seq = GenerateSynthetic(o);
  RunInput in;
  in.name = seq.name;
  in.kind = "synthetic";
  in.camera = seq.camera;
  in.timestamps = seq.timestamps;
  in.gt_world_from_cam = seq.world_from_cam;
  in.observations = seq.observations;
  in.synthetic = std::move(seq);
  return in;
}

PipelineOptions OnlineOptionsFor(bool sequential) {
  PipelineOptions o;
  o.ApplyPreset("outdoor");
  o.mode = "online";
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
  EXPECT_EQ(seq.table.num_observations(), in.observations->num_observations());
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
  // paper's α it splits: docs/benchmarks.md), so the camera is solved against the world.
  const RunInput in = SmallSyntheticInput(1.0);
  PipelineOptions o = OnlineOptionsFor(true);
  o.mode = "batch";
  o.backend.max_iterations = 5;
  o.ApplyAblation("no-i");
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

}  // namespace
}  // namespace cslam
