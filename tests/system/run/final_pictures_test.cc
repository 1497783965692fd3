// The final-state pictures (system/run/final_pictures.h): frames spread over the run, an
// object's points placed by its pose at the frame, and the labelled box drawn on the overlay
// where the true camera saw it, in the colour of the object matched to it.
#include "system/run/final_pictures.h"

#include <gtest/gtest.h>

#include "system/draw/cluster_colors.h"
#include "tests/support/cameras.h"
#include "tests/support/poses.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

using testing::Translation;

TEST(FinalPictures, SpreadFramesTakesTheMiddlesOfEqualStretches) {
  std::vector<int> frames;
  for (int f = 0; f < 154; ++f) frames.push_back(f);
  EXPECT_EQ(SpreadFrames(frames, 3), (std::vector<int>{25, 77, 128}));
  EXPECT_EQ(SpreadFrames({4, 9}, 3), (std::vector<int>{4, 9}));
  EXPECT_TRUE(SpreadFrames(frames, 0).empty());
}

// A camera at the origin looking along z; object 3 at z 10 (frame 0) and z 12 (frame 1), with
// one point 1 m to its left; its truth (id 8, a 4 x 2 x 2 m box) at the same poses.
RunOutputs OneObject() {
  RunOutputs o;
  for (int f = 0; f < 2; ++f) {
    o.camera.frames.push_back(f);
    o.camera.timestamps.push_back(0.1 * f);
    o.camera.poses.push_back(Pose::Identity());
    o.gt_camera = o.camera;
    Trajectory& c = o.clusters[3];
    c.frames.push_back(f);
    c.timestamps.push_back(0.1 * f);
    c.poses.push_back(Translation(0, 0, 10 + 2 * f));
  }
  o.gt_objects[8] = o.clusters[3];
  o.gt_object_match[8] = {"Car", 3};
  o.gt_object_size[8] = {4, 2, 2};
  o.landmarks.push_back({0, 3, 0, 1, Eigen::Vector3d(-1, 0, 12)});  // placed at frame 1
  o.landmarks.push_back({1, 0, 0, 1, Eigen::Vector3d(5, 0, 30)});
  return o;
}

TEST(FinalPictures, AnObjectsPointIsWhereItsPoseAtTheFramePutsIt) {
  const std::vector<RenderPoint> at0 = PointsAtFrame(OneObject(), 0);
  ASSERT_EQ(at0.size(), 2u);
  EXPECT_TRUE(at0[0].p.isApprox(Eigen::Vector3d(-1, 0, 10)));
  EXPECT_EQ(at0[0].cluster, 3);
  EXPECT_TRUE(at0[1].p.isApprox(Eigen::Vector3d(5, 0, 30)));
  EXPECT_TRUE(PointsAtFrame(OneObject(), 5).size() == 1u);  // no pose at 5: the object is not drawn
}

TEST(FinalPictures, TheTrueBoxIsDrawnWhereTheTrueCameraSawItInItsObjectsColour) {
  const StereoCamera camera = testing::KittiSizedCamera();
  const cv::Mat left(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  const cv::Mat image = DrawFinalOverlay(OneObject(), 0, left, camera);
  // The box spans x in [-2, 2] at depth 9..11 m: its near face's left edge at u = 600 - 700*2/9.
  const int u_edge = static_cast<int>(std::lround(600 - 700.0 * 2 / 9));
  const cv::Mat around_edge = image(cv::Rect(u_edge - 3, 140, 7, 80));
  EXPECT_GT(testing::CountColour(around_edge, BgrForCluster(3), 60), 20);
  const cv::Mat far_from_it = image(cv::Rect(20, 280, 60, 60));
  EXPECT_EQ(testing::CountColour(far_from_it, BgrForCluster(3), 60), 0);
}

}  // namespace
}  // namespace cslam
