#include "system/eval/box_labels.h"

#include <gtest/gtest.h>

#include "tests/support/cameras.h"

namespace cslam {
namespace {

StereoCamera Cam() { return testing::KittiSizedCamera(); }

// A box 10 m ahead whose bottom face is 1 m below the camera (camera y is down; box z is up).
ObjectBox BoxAt(int id, double z_ahead) {
  ObjectBox b;
  b.track_id = id;
  b.h = 1.5;
  b.w = 1.8;
  b.l = 4.0;
  Eigen::Matrix3d cam_R_box;
  cam_R_box << 0, -1, 0,  // box y (left) → camera -x
      0, 0, -1,           // box z (up) → camera -y
      1, 0, 0;            // box x (forward) → camera z
  b.cam_from_box.linear() = cam_R_box;
  b.cam_from_box.translation() = Eigen::Vector3d(0, 1.0, z_ahead);
  return b;
}

TEST(BoxLabels, LandmarksInsideAMovingBoxGetItsLabelAndParkedOnesStayStatic) {
  const StereoCamera cam = Cam();
  const int frames = 5;
  // The camera stands still; box 7 drives away 1 m per frame, box 9 is parked at 20 m.
  std::vector<Pose> world_from_cam(frames, Pose::Identity());
  std::vector<std::vector<ObjectBox>> boxes(frames);
  for (int f = 0; f < frames; ++f) boxes[f] = {BoxAt(7, 10.0 + f), BoxAt(9, 20.0)};
  const std::vector<int> moving = MovingTrackIds(boxes, world_from_cam);
  ASSERT_EQ(moving, std::vector<int>{7});

  TrackletTable table;
  auto observe = [&](int landmark, int frame, const Eigen::Vector3d& p) {
    Eigen::Vector3d x;
    ASSERT_TRUE(cam.Project(p, &x));
    table.Add(landmark, frame, x, Eigen::Matrix3d::Identity());
  };
  for (int f = 0; f < frames; ++f) {
    observe(0, f, Eigen::Vector3d(0.3, 0.5, 10.0 + f));  // on the moving box, moves with it
    observe(1, f, Eigen::Vector3d(0.3, 0.5, 20.0));      // on the parked box
    observe(2, f, Eigen::Vector3d(5.0, 0.0, 15.0));      // background
  }
  const std::vector<int> labels = LabelLandmarksByBoxes(table, cam, boxes, moving);
  EXPECT_EQ(labels, (std::vector<int>{1, 0, 0}));

  const auto track = BoxCentreTrajectory(boxes, world_from_cam, 7);
  ASSERT_EQ(track.size(), 5u);
  EXPECT_NEAR(track[0].second.y(), 1.0 - 0.75, 1e-12);  // half the height above the bottom
  EXPECT_NEAR(track[4].second.z(), 14.0, 1e-12);
}

}  // namespace
}  // namespace cslam
