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

TEST(BoxLabels, AFarMoversPointsCountWithinTheirOwnDepthUncertaintyAndACarInFrontOfItDoesNot) {
  // A tram 70–90 m ahead driving away: at that range a keypoint's disparity noise (1 px in
  // each image, √2 px of disparity) is σ_z = z²/(f·b)·√2 ≈ 20–30 m, so a point on it can be
  // measured 8 m short or 10 m past its front and still lie on it; a car parked 30 m ahead,
  // in front of the tram in the image (σ_z ≈ 3.6 m), cannot. (A wall behind the tram cannot be
  // told from it at that range: its own σ_z grows faster than its distance.)
  const StereoCamera cam = Cam();
  const int frames = 4;
  std::vector<Pose> world_from_cam(frames, Pose::Identity());
  std::vector<std::vector<ObjectBox>> boxes(frames);
  for (int f = 0; f < frames; ++f) {
    boxes[f] = {BoxAt(3, 80.0 + 2 * f)};
    boxes[f][0].l = 20.0;  // along z: the tram spans 70..90 m + 2f
    boxes[f][0].h = 3.0;
  }
  ASSERT_EQ(MovingTrackIds(boxes, world_from_cam), std::vector<int>{3});
  TrackletTable table;
  auto observe = [&](int landmark, int frame, const Eigen::Vector3d& p) {
    Eigen::Vector3d x;
    ASSERT_TRUE(cam.Project(p, &x));
    table.Add(landmark, frame, x, Eigen::Matrix3d::Identity());  // σ = 1 px
  };
  for (int f = 0; f < frames; ++f) {
    const double rear = 70.0 + 2 * f;
    observe(0, f, Eigen::Vector3d(0.2, -0.5, rear - 8.0));   // measured 8 m short
    observe(1, f, Eigen::Vector3d(0.2, -0.5, rear + 30.0));  // measured 10 m past its front
    observe(2, f, Eigen::Vector3d(0.2, -0.5, 30.0));         // a parked car in front of it
    observe(3, f, Eigen::Vector3d(3.0, -0.5, rear));         // beside it in the image
  }
  const std::vector<int> labels = LabelLandmarksByBoxes(table, cam, boxes, {3});
  EXPECT_EQ(labels, (std::vector<int>{1, 1, 0, 0}));
  // The old rule, a 3-D box grown by 0.3 m, took none of the tram's points: with a tight
  // depth tolerance the first two are refused as well.
  BoxLabelOptions tight;
  tight.depth_sigmas = 0.01;
  EXPECT_EQ(LabelLandmarksByBoxes(table, cam, boxes, {3}, tight), (std::vector<int>{0, 0, 0, 0}));
}

}  // namespace
}  // namespace cslam
