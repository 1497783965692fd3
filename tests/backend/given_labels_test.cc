#include "backend/given_labels.h"

#include <gtest/gtest.h>

#include "tests/backend/synthetic_bodies.h"

namespace cslam {
namespace {

using testing::BodyScene;
using testing::BodySceneSpec;
using testing::MakeBodyScene;

BodyScene TwoBodies() {
  BodySceneSpec spec;
  spec.num_frames = 20;
  spec.num_static = 150;
  spec.num_moving = 2;
  spec.points_per_body = 40;
  spec.pixel_sigma = 1.0;
  return MakeBodyScene(spec);
}

TEST(GivenLabels, KeepsEveryLabelItIsGiven) {
  const BodyScene scene = TwoBodies();
  const FrameRange range{0, scene.table.num_frames()};
  const BackendResult r =
      RunGivenLabels(scene.table, scene.camera, range, scene.labels, MotionEstimationOptions{});
  EXPECT_EQ(r.method, "true-labels");
  ASSERT_EQ(r.iterations.size(), 1u);
  EXPECT_EQ(r.iterations[0].num_clusters, 3);
  ASSERT_EQ(r.estimate.clusters.size(), 2u);
  for (int l = 0; l < scene.table.num_landmarks(); ++l)
    if (r.estimate.landmark_cluster[l] >= 0) EXPECT_EQ(r.estimate.landmark_cluster[l], scene.labels[l]) << l;
  EXPECT_LT(testing::Ate(r.estimate.world_from_cam, scene.world_from_cam), 0.02);
}

TEST(GivenLabels, LandmarksPastTheLabelsCountAsStatic) {
  const BodyScene scene = TwoBodies();
  const FrameRange range{0, scene.table.num_frames()};
  // No labels at all: every landmark static, as Full BA adjusts them.
  const BackendResult r = RunGivenLabels(scene.table, scene.camera, range, {}, MotionEstimationOptions{});
  EXPECT_TRUE(r.estimate.clusters.empty());
  for (int l = 0; l < scene.table.num_landmarks(); ++l)
    EXPECT_LE(r.estimate.landmark_cluster[l], 0) << l;
}

}  // namespace
}  // namespace cslam
