#include "system/datasets/kitti_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/support/matchers.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

using ::testing::HasSubstr;
using testing::RawDateDir;

TEST(KittiCalibration, KeyValueFileParsesNumbersAndRemembersLines) {
  testing::TempDir tmp("kv");
  const auto file = tmp.path() / "c.txt";
  testing::WriteText(file, "calib_time: 09-Jan-2012 13:57:47\n\nA: 1 2.5e1 -3\nB:\n");
  const KeyValueFile kv = KeyValueFile::Read(file.string());
  EXPECT_EQ(kv.Numbers("A", 3), (std::vector<double>{1, 25, -3}));
  EXPECT_EQ(kv.LineOf("A"), 3);
  EXPECT_EQ(kv.Numbers("B", 0), std::vector<double>{});
  // Non-numeric keys are fine until someone asks for their numbers.
  EXPECT_THAT(testing::InputErrorMessage([&] { kv.Numbers("calib_time", 2); }),
              HasSubstr(file.string() + ":1: 'calib_time' field 1: expected a finite number"));
  EXPECT_THAT(testing::InputErrorMessage([&] { kv.Numbers("A", 4); }),
              HasSubstr(file.string() + ":3: 'A': expected 4 numbers, got 3"));
  EXPECT_THAT(testing::InputErrorMessage([&] { kv.Numbers("C", 1); }),
              HasSubstr(file.string() + ": missing key 'C:'"));
}

TEST(KittiCalibration, KeyValueFileRejectsDuplicatesAndLinesWithoutKey) {
  testing::TempDir tmp("kv_bad");
  const auto file = tmp.path() / "c.txt";
  testing::WriteText(file, "A: 1\nA: 2\n");
  EXPECT_THAT(testing::InputErrorMessage([&] { KeyValueFile::Read(file.string()); }),
              HasSubstr(file.string() + ":2: key 'A' appears twice"));
  testing::WriteText(file, "A: 1\n1 2 3\n");
  EXPECT_THAT(testing::InputErrorMessage([&] { KeyValueFile::Read(file.string()); }),
              HasSubstr(file.string() + ":2: expected a line 'key: values'"));
}

TEST(KittiCalibration, HugeImageSizeIsAnInputErrorNotAnOverflow) {
  // Regression of fuzz/corpus/calibration/crash-s_rect_int_overflow: 1.24e103 was converted
  // to int (undefined behaviour) instead of being rejected.
  testing::TempDir tmp("s_rect_huge");
  const auto file = tmp.path() / "calib_cam_to_cam.txt";
  testing::WriteText(file, "R_rect_00: 1 0 0 0 1 0 0 0 1\nS_rect_00: 1.24e+103 3.75e+02\n");
  EXPECT_THAT(testing::InputErrorMessage([&] { ReadKittiCamToCam(file.string()); }),
              HasSubstr(file.string() + ":2: 'S_rect_00': expected a positive whole image size"));
  testing::WriteText(file, "R_rect_00: 1 0 0 0 1 0 0 0 1\nS_rect_00: 1242 375\n");
  EXPECT_EQ(ReadKittiCamToCam(file.string()).s_rect[0]->x(), 1242);
}

TEST(KittiCalibration, ColourPairBaselineAndCamera02Offset) {
  const KittiCamToCam calib = ReadKittiCamToCam((RawDateDir() / "calib_cam_to_cam.txt").string());
  const StereoCamera grey = StereoCameraFromCamToCam(calib, 0, 1);
  EXPECT_NEAR(grey.baseline, 0.537151, 1e-5);
  const StereoCamera colour = StereoCameraFromCamToCam(calib, 2, 3);
  EXPECT_NEAR(colour.baseline, 0.532712, 1e-5);
  // Camera 02 sits ~6 cm to the right of camera 00 (x-offset −P[0,3]/fx would say −0.0622 m;
  // the exact K⁻¹·P[:,3] includes the y and z terms).
  const Pose cam2_from_cam0 = CamFromCam0Rect(calib, 2);
  const Eigen::Matrix3d k = calib.p_rect[2]->leftCols<3>();
  EXPECT_TRUE(testing::MatrixNear(k * cam2_from_cam0.translation(), calib.p_rect[2]->col(3), 1e-9));
  EXPECT_NEAR(cam2_from_cam0.translation().x(), 0.06, 0.01);
  EXPECT_TRUE(testing::MatrixNear(CamFromCam0Rect(calib, 0).matrix(), Pose::Identity().matrix(), 1e-12));
}

TEST(KittiCalibration, RigidCalibrationFilesReadRAndT) {
  const Pose cam_from_velo = ReadKittiRigidCalibration((RawDateDir() / "calib_velo_to_cam.txt").string());
  // Velodyne x (forward) is camera z; velodyne z (up) is camera −y.
  EXPECT_GT((cam_from_velo.linear() * Eigen::Vector3d::UnitX()).z(), 0.99);
  EXPECT_LT((cam_from_velo.linear() * Eigen::Vector3d::UnitZ()).y(), -0.99);
  EXPECT_TRUE(testing::MatrixNear(cam_from_velo.translation(),
                                  Eigen::Vector3d(-4.069766e-03, -7.631618e-02, -2.717806e-01), 1e-12));
}

TEST(KittiCalibration, OdometryCalibReadsTheOptionalTrLine) {
  testing::TempDir tmp("odo_calib_tr");
  const auto file = tmp.path() / "calib.txt";
  const std::string p = "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 600 -350 0 700 180 0 0 0 1 0\n";
  testing::WriteText(file, p);
  const KittiOdometryCalib without = ReadKittiOdometryCalibration(file.string());
  EXPECT_FALSE(without.cam0_from_velo.has_value());
  EXPECT_DOUBLE_EQ(without.camera.baseline, 0.5);
  testing::WriteText(file, p + "Tr: 0 -1 0 0.1 0 0 -1 0.2 1 0 0 0.3\n");
  const KittiOdometryCalib with = ReadKittiOdometryCalibration(file.string());
  ASSERT_TRUE(with.cam0_from_velo.has_value());
  EXPECT_TRUE(testing::MatrixNear(*with.cam0_from_velo * Eigen::Vector3d(1, 0, 0),
                                  Eigen::Vector3d(0.1, 0.2, 1.3), 1e-12));
  testing::WriteText(file, p + "Tr: 1 1 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(testing::InputErrorMessage([&] { ReadKittiOdometryCalibration(file.string()); }),
              HasSubstr(file.string() + ":3: 'Tr': expected a rotation matrix"));
}

}  // namespace
}  // namespace cslam
