#include "system/datasets/kitti_odometry_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "system/datasets/dataset.h"
#include "tests/support/matchers.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

using testing::OdometrySequenceDir;

TEST(KittiOdometry, LoadsTheClipWithCalibrationAndTimes) {
  const KittiOdometrySource src(OdometrySequenceDir().string());
  EXPECT_EQ(src.name(), "clip_a");
  EXPECT_EQ(src.kind(), "kitti_odometry");
  ASSERT_EQ(src.size(), 51);
  EXPECT_EQ(src.camera().width, 1226);
  EXPECT_EQ(src.camera().height, 370);
  EXPECT_DOUBLE_EQ(src.camera().fx, 7.070912e+02);
  EXPECT_DOUBLE_EQ(src.camera().cy, 1.831104e+02);
  // b = −P1[0,3] / P1[0,0] = 379.8145 / 707.0912.
  EXPECT_NEAR(src.camera().baseline, 379.8145 / 707.0912, 1e-12);
  EXPECT_NEAR(src.camera().baseline, 0.537, 0.001);
  ASSERT_EQ(src.timestamps().size(), 51u);
  EXPECT_EQ(src.timestamps()[0], 0.0);
  EXPECT_NEAR(src.timestamps()[50], 50 * 0.1036, 1e-9);
  const StereoFrame f = src.Load(50);
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_EQ(f.right.cols, 1226);
  EXPECT_EQ(f.right.rows, 370);
}

TEST(KittiOdometry, GroundTruthFromThePosesFile) {
  const KittiOdometrySource src(OdometrySequenceDir().string());
  const auto gt = src.GroundTruth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 51u);
  EXPECT_TRUE(testing::PoseNear((*gt)[0], Pose::Identity(), 1e-9, 1e-9));
  // Line 2 of poses/clip_a.txt: t = (−0.01401751, −0.02820321, 1.198998).
  EXPECT_TRUE(testing::MatrixNear((*gt)[1].translation(),
                                  Eigen::Vector3d(-1.401751e-02, -2.820321e-02, 1.198998), 1e-6));
  double length = 0;
  for (size_t k = 1; k < gt->size(); ++k)
    length += ((*gt)[k].translation() - (*gt)[k - 1].translation()).norm();
  EXPECT_NEAR(length, 60.0, 3.0);
  // Straight driving along the camera's +z.
  EXPECT_GT(gt->back().translation().z(), 0.95 * gt->back().translation().norm());
}

TEST(KittiOdometry, PoseFileIsReExpressedRelativeToItsFirstLine) {
  testing::TempDir tmp("odo_rebase");
  const auto poses = testing::Lines(testing::ReadText(testing::SharedData() / "kitti_odometry" /
                                                      "poses" / "clip_a.txt"));
  // Drop the first 10 lines: the new first line is far from the identity.
  testing::WriteText(tmp.path() / "p.txt",
                     testing::JoinLines(std::vector<std::string>(poses.begin() + 10, poses.end())));
  const std::vector<Pose> all = ReadKittiPoseFile(
      (testing::SharedData() / "kitti_odometry" / "poses" / "clip_a.txt").string());
  const std::vector<Pose> clipped = ReadKittiPoseFile((tmp.path() / "p.txt").string(), 41);
  EXPECT_TRUE(testing::PoseNear(clipped[0], Pose::Identity(), 1e-12, 1e-12));
  EXPECT_TRUE(testing::PoseNear(clipped[30], all[10].inverse() * all[40], 1e-9, 1e-9));
}

TEST(Dataset, DetectsAndOpensBothKittiKinds) {
  EXPECT_EQ(DetectDataset(testing::RawDriveDir().string()), DatasetKind::kKittiRaw);
  EXPECT_EQ(DetectDataset(OdometrySequenceDir().string()), DatasetKind::kKittiOdometry);
  EXPECT_EQ(DetectDataset(testing::SharedData().string()), DatasetKind::kUnknown);
  EXPECT_EQ(DetectDataset("/nonexistent/cslam"), DatasetKind::kUnknown);
  // A trailing slash must not change the sequence name.
  const auto src = OpenStereoSource(OdometrySequenceDir().string() + "/");
  EXPECT_EQ(src->kind(), "kitti_odometry");
  EXPECT_EQ(src->name(), "clip_a");
}

TEST(Dataset, DetectsASyntheticSequenceByItsObservationsFile) {
  testing::TempDir tmp("synthetic_detect");
  testing::WriteText(tmp.path() / "observations.csv", "not read here\n");
  EXPECT_EQ(DetectDataset(tmp.path().string()), DatasetKind::kSynthetic);
  EXPECT_THAT(testing::InputErrorMessage([&] { OpenStereoSource(tmp.path().string()); }),
              ::testing::HasSubstr("synthetic"));
}

}  // namespace
}  // namespace cslam
