// The calibration files users already have read into one StereoRig, and the rig mistakes the
// issue lists (millimetres, an inverted T, unknown or mixed models) refused with their hint.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "system/datasets/rig_calibration.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using testing::InputErrorMessage;

fs::path EurocCam(int i) {
  return testing::SharedData() / "euroc" / "V1_01_easy_first50" / "mav0" / ("cam" + std::to_string(i)) / "sensor.yaml";
}

// The EuRoC V1 rig as Kalibr writes it (cam1's T_cn_cnm1 from the sensor.yaml pair, 9 digits).
constexpr const char* kCamchain = R"(cam0:
  camera_model: pinhole
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  distortion_model: radtan
  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
  resolution: [752, 480]
  rostopic: /cam0/image_raw
cam1:
  T_cn_cnm1:
  - [0.999997256, 0.002312067, 0.000376008, -0.110073808]
  - [-0.002317135, 0.999898048, 0.014089835, 0.000399121]
  - [-0.000343393, -0.014090668, 0.999900662, -0.000853702]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  intrinsics: [457.587, 456.134, 379.999, 255.238]
  distortion_model: radtan
  distortion_coeffs: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]
  resolution: [752, 480]
)";

// OpenCV FileStorage output of a stereo calibration, with the unit this project requires.
constexpr const char* kOpenCv = R"(%YAML:1.0
---
image_width: 752
image_height: 480
unit: mm
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 458.654, 0., 367.215, 0., 457.296, 248.375, 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0. ]
M2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 457.587, 0., 379.999, 0., 456.134, 255.238, 0., 0., 1. ]
D2: !!opencv-matrix
   rows: 1
   cols: 4
   dt: d
   data: [ -0.28368365, 0.07451284, -0.00010473, -3.55590700e-05 ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 0.999997256, 0.002312067, 0.000376008, -0.002317135, 0.999898048, 0.014089835, -0.000343393, -0.014090668, 0.999900662 ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -110.073808, 0.399121, -0.853702 ]
)";

constexpr const char* kOrbSlam3 = R"(%YAML:1.0
File.version: "1.0"
Camera.type: "KannalaBrandt8"
Camera1.fx: 366.163
Camera1.fy: 365.631
Camera1.cx: 380.573
Camera1.cy: 225.950
Camera1.k1: -0.020476443
Camera1.k2: -0.007108226
Camera1.k3: 0.002180580
Camera1.k4: -0.001192386
Camera2.fx: 367.032
Camera2.fy: 366.632
Camera2.cx: 379.304
Camera2.cy: 236.659
Camera2.k1: -0.019659843
Camera2.k2: -0.005079736
Camera2.k3: -0.001357391
Camera2.k4: 0.000419038
Camera.width: 752
Camera.height: 480
Stereo.T_c1_c2: !!opencv-matrix
  rows: 4
  cols: 4
  dt: f
  data: [1.0, 0.0, 0.0, 0.12, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
)";

class RigFiles : public ::testing::Test {
 protected:
  RigFiles() : tmp_(::testing::UnitTest::GetInstance()->current_test_info()->name()) {}
  fs::path Write(const std::string& name, const std::string& text) {
    testing::WriteText(tmp_.path() / name, text);
    return tmp_.path() / name;
  }
  testing::TempDir tmp_;
};

std::string Replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("test text lacks '" + from + "'");
  return text.replace(at, from.size(), to);
}

TEST(RigCalibration, AnEurocSensorPairStartingWithYamlColonDirectiveReads) {
  const StereoRig rig = ReadEurocSensorPair(EurocCam(0).string(), EurocCam(1).string());
  EXPECT_EQ(rig.format, "euroc");
  EXPECT_DOUBLE_EQ(rig.cam0.fx, 458.654);
  EXPECT_DOUBLE_EQ(rig.cam1.cy, 255.238);
  EXPECT_EQ(rig.cam0.width, 752);
  EXPECT_EQ(rig.cam0.lens, LensModel::kRadialTangential);
  ASSERT_EQ(rig.cam1.distortion.size(), 4u);
  // The README's T_cam0_cam1 = T_BS(cam0)⁻¹ · T_BS(cam1): a 0.110 m baseline, cam1 at +x.
  EXPECT_NEAR(rig.Baseline(), 0.1101, 5e-4);
  EXPECT_LT(rig.cam1_from_cam0.translation().x(), -0.10);
  ASSERT_TRUE(rig.body_from_cam0.has_value());
  EXPECT_NEAR(rig.body_from_cam0->translation().x(), -0.0216401454975, 1e-12);
  EXPECT_NO_THROW(CheckStereoRig(rig));
}

TEST_F(RigFiles, AKalibrCamchainGivesTheSameRigAsTheSensorPair) {
  const StereoRig kalibr = ReadRigCalibration(Write("camchain.yaml", kCamchain).string());
  const StereoRig euroc = ReadEurocSensorPair(EurocCam(0).string(), EurocCam(1).string());
  EXPECT_EQ(kalibr.format, "kalibr");
  EXPECT_DOUBLE_EQ(kalibr.cam1.fx, euroc.cam1.fx);
  EXPECT_LT((kalibr.cam1_from_cam0.matrix() - euroc.cam1_from_cam0.matrix()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_FALSE(kalibr.body_from_cam0.has_value());
}

TEST_F(RigFiles, AnOpenCvCalibrationWithOpencvMatricesInMillimetresReadsInMetres) {
  const StereoRig rig = ReadRigCalibration(Write("stereo.yml", kOpenCv).string());
  EXPECT_EQ(rig.format, "opencv");
  EXPECT_DOUBLE_EQ(rig.cam0.cx, 367.215);
  EXPECT_EQ(rig.cam0.distortion.size(), 5u);
  EXPECT_EQ(rig.cam1.distortion.size(), 4u);
  EXPECT_NEAR(rig.cam1_from_cam0.translation().x(), -0.110073808, 1e-12);
  EXPECT_FALSE(rig.given_rectification.has_value());
  EXPECT_NO_THROW(CheckStereoRig(rig));
}

TEST_F(RigFiles, AnOpenCvCalibrationWithoutAUnitIsRefusedNamingTheKey) {
  const fs::path f = Write("stereo.yml", Replaced(kOpenCv, "unit: mm\n", ""));
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(f.string()); }),
              AllOf(HasSubstr(f.string()), HasSubstr("'unit': missing; expected the unit of T (m, cm or mm)")));
}

TEST_F(RigFiles, AnOpenCvCalibrationInMillimetresCalledMetresIsRefusedAsMillimetres) {
  const fs::path f = Write("stereo.yml", Replaced(kOpenCv, "unit: mm", "unit: m"));
  const StereoRig rig = ReadRigCalibration(f.string());
  EXPECT_THAT(InputErrorMessage([&] { CheckStereoRig(rig); }),
              AllOf(HasSubstr(f.string()), HasSubstr("the baseline is 110.1 m"), HasSubstr("millimetres?")));
}

TEST_F(RigFiles, AnInvertedTIsRefusedWithKalibrsConvention) {
  const fs::path f = Write("camchain.yaml", Replaced(kCamchain, "-0.110073808]", "0.110073808]"));
  const StereoRig rig = ReadRigCalibration(f.string());
  EXPECT_THAT(InputErrorMessage([&] { CheckStereoRig(rig); }),
              AllOf(HasSubstr(f.string()), HasSubstr("T looks inverted: Kalibr's T_cn_cnm1 maps cam0 to cam1")));
}

TEST_F(RigFiles, ATranslationNotAlongXIsRefused) {
  const fs::path f = Write("camchain.yaml", Replaced(Replaced(kCamchain, "-0.110073808]", "-0.01]"),
                                                     "0.000399121]", "0.11]"));
  const StereoRig rig = ReadRigCalibration(f.string());
  EXPECT_THAT(InputErrorMessage([&] { CheckStereoRig(rig); }), HasSubstr("is not mostly along x"));
}

TEST_F(RigFiles, AnUnknownDistortionModelIsNamedWithItsLine) {
  const fs::path f = Write("camchain.yaml", Replaced(kCamchain, "distortion_model: radtan", "distortion_model: fov"));
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(f.string()); }),
              AllOf(HasSubstr(f.string() + ":4: 'distortion_model': unknown distortion model 'fov'"),
                    HasSubstr("expected radtan (radial-tangential), equidistant (fisheye) or none")));
}

TEST_F(RigFiles, MixedDistortionModelsAreRefused) {
  std::string text = kCamchain;
  text.replace(text.rfind("distortion_model: radtan"), 24, "distortion_model: equidistant");
  const StereoRig rig = ReadRigCalibration(Write("camchain.yaml", text).string());
  EXPECT_THAT(InputErrorMessage([&] { CheckStereoRig(rig); }),
              HasSubstr("mixed distortion models: cam0 is radtan, cam1 equidistant"));
}

TEST_F(RigFiles, AWrongCoefficientCountIsRefused) {
  const StereoRig rig = ReadRigCalibration(
      Write("camchain.yaml", Replaced(kCamchain, "[-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]",
                                      "[-0.28340811, 0.07395907, 0.00019359]"))
          .string());
  EXPECT_THAT(InputErrorMessage([&] { CheckStereoRig(rig); }),
              HasSubstr("cam0: expected 4 or 5 radial-tangential coefficients (k1 k2 p1 p2 [k3]), got 3"));
}

TEST_F(RigFiles, AnOrbSlam3FisheyeSettingsFileReads) {
  const StereoRig rig = ReadRigCalibration(Write("settings.yaml", kOrbSlam3).string());
  EXPECT_EQ(rig.format, "orbslam3");
  EXPECT_EQ(rig.cam0.lens, LensModel::kEquidistant);
  EXPECT_DOUBLE_EQ(rig.cam1.distortion[3], 0.000419038);
  // T_c1_c2 places camera 2 at +0.12 m in camera 1: cam1_from_cam0 has x = -0.12.
  EXPECT_NEAR(rig.cam1_from_cam0.translation().x(), -0.12, 1e-7);
  EXPECT_NO_THROW(CheckStereoRig(rig));
}

TEST_F(RigFiles, AWrongMatrixSizeIsNamedWithItsKey) {
  const fs::path f = Write("stereo.yml", Replaced(kOpenCv, "   rows: 3\n   cols: 1", "   rows: 1\n   cols: 3"));
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(f.string()); }),
              HasSubstr("'T': expected a 3x1 matrix, got 1x3"));
}

TEST_F(RigFiles, ASingleSensorYamlOrAnUnknownFileIsRefusedWithWhatIsExpected) {
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(EurocCam(0).string()); }),
              HasSubstr("is one camera's EuRoC sensor.yaml"));
  const fs::path f = Write("other.yaml", "a: 1\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(f.string()); }),
              HasSubstr("is none of the known stereo calibrations"));
  const fs::path bad = Write("bad.yaml", "cam0: [1, 2\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadRigCalibration(bad.string()); }), HasSubstr("not valid YAML"));
}

TEST_F(RigFiles, TheRigWrittenAsACamchainReadsBackTheSame) {
  const StereoRig rig = ReadEurocSensorPair(EurocCam(0).string(), EurocCam(1).string());
  const StereoRig back = ReadKalibrCamchain(Write("rig.yaml", KalibrCamchainText(rig)).string());
  EXPECT_DOUBLE_EQ(back.cam0.fx, rig.cam0.fx);
  EXPECT_EQ(back.cam1.distortion, rig.cam1.distortion);
  EXPECT_LT((back.cam1_from_cam0.matrix() - rig.cam1_from_cam0.matrix()).cwiseAbs().maxCoeff(), 1e-10);
  ASSERT_TRUE(back.body_from_cam0.has_value());
  EXPECT_LT((back.body_from_cam0->matrix() - rig.body_from_cam0->matrix()).cwiseAbs().maxCoeff(), 1e-10);
}

}  // namespace
}  // namespace cslam
