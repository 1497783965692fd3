// The ASL/EuRoC layout on the shared EuRoC clip and on edited copies of it: pairing by
// timestamp, ground truth carried to the rectified camera, the calibration check, and each
// bad input of the list named with its file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <iostream>

#include "system/datasets/asl_layout.h"
#include "system/datasets/dataset.h"
#include "system/datasets/rig_image_check.h"
#include "system/datasets/stereo_folder.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using testing::InputErrorMessage;
using testing::Lines;
using testing::ReadText;
using testing::WriteText;

fs::path Euroc() { return testing::SharedData() / "euroc" / "V1_01_easy_first50"; }
fs::path EurocGt() { return Euroc() / "groundtruth_tum.txt"; }

double PathLength(const std::vector<Pose>& poses) {
  double len = 0;
  for (size_t i = 1; i < poses.size(); ++i) len += (poses[i].translation() - poses[i - 1].translation()).norm();
  return len;
}

TEST(AslLayout, TheSharedEurocClipOpensAsFiftyRectifiedPairsWithGroundTruth) {
  ASSERT_EQ(DetectDataset(Euroc().string()), DatasetKind::kAsl);
  const auto src = OpenStereoSource(Euroc().string(), {false, "", EurocGt().string()});
  EXPECT_EQ(src->kind(), "euroc");
  EXPECT_EQ(src->size(), 50);
  EXPECT_NEAR(src->timestamps()[1], 0.05, 1e-6);
  EXPECT_NEAR(src->camera().baseline, 0.1101, 5e-4);
  const auto gt = src->GroundTruth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 50u);
  EXPECT_TRUE(gt->front().isApprox(Pose::Identity()));
  // The README: the drone moves a few millimetres in this stretch.
  EXPECT_LT(PathLength(*gt), 0.02);
  EXPECT_GT(PathLength(*gt), 0.0005);
  const StereoFrame f = src->Load(49);
  EXPECT_EQ(f.left.cols, 752);
  EXPECT_EQ(f.left.type(), CV_8UC1);
}

TEST(AslLayout, GroundTruthIsOfTheRectifiedLeftCameraNotTheBody) {
  const auto src = OpenAslSequence(Euroc().string(), "", EurocGt().string());
  const TimedPoses body = ReadTumPoses(EurocGt().string());
  // Recompute frame 10's camera motion from the body poses by hand: rect0 ← body through T_BS
  // and the rectifying rotation.
  Pose body_from_rect = *src->rig().body_from_cam0;
  body_from_rect.linear() = body_from_rect.linear() * src->rectifier().rect0_from_cam0().transpose();
  const std::vector<double> t0 = {1403715273.262142976}, t10 = {1403715273.762142976};
  const Pose w0 = InterpolatePoses(body, t0).front() * body_from_rect;
  const Pose w10 = InterpolatePoses(body, t10).front() * body_from_rect;
  const Pose expected = w0.inverse() * w10;
  const Pose got = (*src->GroundTruth())[10];
  EXPECT_LT((got.translation() - expected.translation()).norm(), 1e-6);
  EXPECT_LT(RotationAngle(got.linear().transpose() * expected.linear()), 1e-6);
}

TEST(AslLayout, TheCalibrationCheckFindsTheRowsAlignedOnEuroc) {
  const auto src = OpenAslSequence(Euroc().string(), "", "");
  const RigImageCheck check = CheckRigOnImages(*src, {0, 12, 24, 36, 49});
  std::cout << "EuRoC vertical offsets: median " << check.rectified.median << " px, p90 " << check.rectified.p90
            << " px (" << check.rectified.matches << " matches); raw median " << check.raw.median << " px\n";
  EXPECT_TRUE(check.ok) << check.problem;
  EXPECT_LE(check.rectified.median, 0.5);
  EXPECT_GT(check.raw.median, 5.0);  // the raw pair is not row-aligned: the check can fail
}

// An editable copy of the first `frames` pairs: images symlinked, text files copied.
class AslBadInput : public ::testing::Test {
 protected:
  static constexpr int kFrames = 6;
  AslBadInput() : tmp_(::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    seq_ = tmp_.path() / "seq";
    for (const char* cam : {"cam0", "cam1"}) {
      const fs::path from = Euroc() / "mav0" / cam, to = seq_ / "mav0" / cam;
      WriteText(to / "sensor.yaml", ReadText(from / "sensor.yaml"));
      const auto lines = Lines(ReadText(from / "data.csv"));
      WriteText(to / "data.csv", testing::JoinLines({lines.begin(), lines.begin() + 1 + kFrames}));
      fs::create_directories(to / "data");
      for (int i = 1; i <= kFrames; ++i) {
        const std::string name = lines[static_cast<size_t>(i)].substr(lines[static_cast<size_t>(i)].find(',') + 1);
        fs::create_symlink(from / "data" / name, to / "data" / name);
      }
    }
  }
  fs::path Cam(int i) const { return seq_ / "mav0" / ("cam" + std::to_string(i)); }
  std::string Open(const std::string& gt = "") {
    return InputErrorMessage([&] { OpenAslSequence(seq_.string(), "", gt); });
  }
  testing::TempDir tmp_;
  fs::path seq_;
};

TEST_F(AslBadInput, TheUneditedCopyOpens) { EXPECT_EQ(OpenAslSequence(seq_.string(), "", "")->size(), kFrames); }

TEST_F(AslBadInput, AMissingSensorYamlIsNamed) {
  fs::remove(Cam(1) / "sensor.yaml");
  EXPECT_THAT(Open(), HasSubstr((Cam(1) / "sensor.yaml").string() +
                                ": missing: expected the camera's calibration (EuRoC sensor.yaml)"));
}

TEST_F(AslBadInput, ADataCsvNamingAMissingImageIsNamedWithItsLine) {
  const fs::path first = *fs::directory_iterator(Cam(0) / "data");
  const auto lines = Lines(ReadText(Cam(0) / "data.csv"));
  for (const auto& e : fs::directory_iterator(Cam(0) / "data"))
    if (lines[3].find(e.path().filename().string()) != std::string::npos) fs::remove(e.path());
  EXPECT_THAT(Open(), AllOf(HasSubstr((Cam(0) / "data.csv").string() + ":4: names the image "),
                            HasSubstr(", which is missing")));
}

TEST_F(AslBadInput, OneCameraWithMoreFramesKeepsThePairsThatMatchInTime) {
  auto lines = Lines(ReadText(Cam(1) / "data.csv"));
  lines.erase(lines.begin() + 3);  // cam1 loses its third frame: cam0's third has no partner
  WriteText(Cam(1) / "data.csv", testing::JoinLines(lines));
  const auto src = OpenAslSequence(seq_.string(), "", "");
  EXPECT_EQ(src->size(), kFrames - 1);
  // Pairs are matched by time, not by position: the frame after the gap is 0.15 s in.
  EXPECT_NEAR(src->timestamps()[2], 0.15, 1e-6);
}

TEST_F(AslBadInput, CamerasWithNoCommonTimestampAreRefused) {
  auto lines = Lines(ReadText(Cam(1) / "data.csv"));
  for (size_t i = 1; i < lines.size(); ++i) {  // every cam1 time 1 ns later, the files unchanged
    const size_t comma = lines[i].find(',');
    lines[i] = std::to_string(std::stoll(lines[i].substr(0, comma)) + 1) + lines[i].substr(comma);
  }
  WriteText(Cam(1) / "data.csv", testing::JoinLines(lines));
  EXPECT_THAT(Open(), HasSubstr((Cam(1) / "data.csv").string() +
                                ": no timestamp of cam1 equals one of cam0"));
}

TEST_F(AslBadInput, ACalibrationOfAnotherResolutionIsRefusedNamingTheImageAndTheFile) {
  testing::ReplaceLine(Cam(0) / "sensor.yaml", "resolution:", "resolution: [640, 480]");
  testing::ReplaceLine(Cam(1) / "sensor.yaml", "resolution:", "resolution: [640, 480]");
  EXPECT_THAT(Open(), AllOf(HasSubstr("expected a 640x480 image as the calibration says"),
                            HasSubstr("sensor.yaml"), HasSubstr("got 752x480")));
}

TEST_F(AslBadInput, GroundTruthNotCoveringTheImagesIsRefused) {
  const auto lines = Lines(ReadText(EurocGt()));
  WriteText(tmp_.path() / "short_gt.txt", testing::JoinLines({lines.begin(), lines.begin() + 4}));
  EXPECT_THAT(Open((tmp_.path() / "short_gt.txt").string()),
              AllOf(HasSubstr("short_gt.txt: does not cover image 3"),
                    HasSubstr("expected poses from before the first to after the last image")));
}

TEST_F(AslBadInput, SixteenBitImagesReadAsTheEightBitOnesTheyWereMadeFrom) {
  for (int cam : {0, 1})
    for (const auto& e : fs::directory_iterator(Cam(cam) / "data")) {
      const cv::Mat eight = cv::imread(e.path().string(), cv::IMREAD_GRAYSCALE);
      cv::Mat sixteen;
      eight.convertTo(sixteen, CV_16U, 256.0);
      fs::remove(e.path());
      cv::imwrite(e.path().string(), sixteen);
    }
  const auto converted = OpenAslSequence(seq_.string(), "", "");
  const auto original = OpenAslSequence(Euroc().string(), "", "");
  EXPECT_EQ(cv::countNonZero(converted->LoadRaw(2).left != original->LoadRaw(2).left), 0);
}

TEST_F(AslBadInput, AlreadyRectifiedImagesWithDistortionCoefficientsAreNamedAsSuch) {
  // Write each pair as the rectifier outputs it, then read it again with the raw calibration.
  const auto original = OpenAslSequence(Euroc().string(), "", "");
  const auto lines0 = Lines(ReadText(Cam(0) / "data.csv"));
  for (int i = 0; i < kFrames; ++i) {
    const StereoFrame f = original->Load(i);
    const std::string name = lines0[static_cast<size_t>(i + 1)].substr(lines0[static_cast<size_t>(i + 1)].find(',') + 1);
    for (int cam : {0, 1}) {
      fs::remove(Cam(cam) / "data" / name);
      cv::imwrite((Cam(cam) / "data" / name).string(), cam == 0 ? f.left : f.right);
    }
  }
  const auto src = OpenAslSequence(seq_.string(), "", "");
  const RigImageCheck check = CheckRigOnImages(*src, {0, 5});
  EXPECT_FALSE(check.ok);
  EXPECT_THAT(check.problem, HasSubstr("are these images already rectified?"));
}

TEST(StereoFolder, APlainFolderWithoutCalibIsRefusedWithWhatToGive) {
  testing::TempDir tmp("plain_no_calib");
  fs::create_directories(tmp.path() / "left");
  fs::create_directories(tmp.path() / "right");
  EXPECT_EQ(DetectDataset(tmp.path().string()), DatasetKind::kStereoFolder);
  EXPECT_THAT(InputErrorMessage([&] { OpenStereoSource(tmp.path().string()); }),
              HasSubstr("is a plain stereo folder (left/, right/): expected its calibration with --calib FILE"));
}

TEST(StereoFolder, CalibOrGtGivenForAKittiFolderIsRefusedNotIgnored) {
  EXPECT_THAT(InputErrorMessage([] {
                OpenStereoSource(testing::OdometrySequenceDir().string(), {false, "calib.yaml", ""});
              }),
              HasSubstr("is a KITTI folder, which carries its own calibration and ground truth; expected no --calib"));
}

}  // namespace
}  // namespace cslam
