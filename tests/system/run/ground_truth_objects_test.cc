// The labelled objects' truth exported as objects_gt/ (system/run/ground_truth_objects.h):
// the generator's poses for a synthetic sequence, the moving boxes' centre poses carried to
// the world for KITTI raw, only over the frames processed.
#include "system/run/ground_truth_objects.h"

#include <gtest/gtest.h>

#include "system/eval/box_labels.h"
#include "tests/support/poses.h"

namespace cslam {
namespace {

using testing::Translation;

TEST(GroundTruthObjects, ASyntheticObjectIsTheGeneratorsPoseAtEachFrameProcessed) {
  RunInput input;
  SyntheticSequence seq;
  seq.world_from_object.assign(3, std::vector<Pose>(6, Pose::Identity()));
  for (int f = 0; f < 6; ++f) {
    input.timestamps.push_back(0.1 * f);
    seq.world_from_object[1][f] = Translation(f, 0, 10);
    seq.world_from_object[2][f] = Translation(-2, 0, 5 + 2 * f);
  }
  input.synthetic = seq;
  const auto objects = GroundTruthObjects(input, 4);
  ASSERT_EQ(objects.size(), 2u);
  const Trajectory& t = objects.at(2).trajectory;
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t.frames.back(), 3);
  EXPECT_DOUBLE_EQ(t.timestamps[3], 0.3);
  EXPECT_TRUE(t.poses[3].isApprox(Translation(-2, 0, 11)));
}

TEST(GroundTruthObjects, AKittiBoxThatMovesIsExportedAtItsCentreAndAParkedOneIsNot) {
  // The camera drives 1 m per frame along z; box 7 drives 2 m per frame ahead of it, box 9 is
  // parked (it falls back by 1 m per frame in the camera).
  RunInput input;
  input.gt_world_from_cam.emplace();
  input.gt_boxes.resize(8);
  for (int f = 0; f < 8; ++f) {
    input.timestamps.push_back(0.1 * f);
    input.gt_world_from_cam->push_back(Translation(0, 0, f));
    ObjectBox moving{7, "Van", Translation(1, 1.6, 10 + f), 2.0, 1.8, 4.5};
    ObjectBox parked{9, "Car", Translation(-3, 1.6, 20 - f), 1.5, 1.7, 4.0};
    input.gt_boxes[f] = {moving, parked};
  }
  const auto objects = GroundTruthObjects(input, 8);
  ASSERT_EQ(objects.size(), 1u);
  const GroundTruthObject& van = objects.at(7);
  EXPECT_EQ(van.type, "Van");
  ASSERT_EQ(van.trajectory.size(), 8u);
  const auto centres = BoxCentreTrajectory(input.gt_boxes, *input.gt_world_from_cam, 7);
  for (size_t k = 0; k < centres.size(); ++k)
    EXPECT_TRUE(van.trajectory.poses[k].translation().isApprox(centres[k].second)) << k;
  // Frame 5: camera at z 5, box origin 15 ahead of it, centre h/2 = 1 up the box's z axis
  // (the box is not rotated here).
  EXPECT_NEAR(van.trajectory.poses[5].translation().z(), 5 + 15 + 1, 1e-12);
}

}  // namespace
}  // namespace cslam
