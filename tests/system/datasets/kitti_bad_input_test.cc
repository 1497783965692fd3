// Every kind of bad input must end in an InputError naming the file (and line) and what was
// expected — never a crash. Each test edits a small copy of the real data in a temp folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "system/datasets/dataset.h"
#include "system/datasets/kitti_odometry_reader.h"
#include "system/datasets/kitti_raw_reader.h"
#include "system/datasets/kitti_tracklets.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using testing::InputErrorMessage;
using testing::LineStartingWith;
using testing::ReplaceLine;

constexpr int kFrames = 5;

std::string OpenRaw(const fs::path& drive) {
  return InputErrorMessage([&] { KittiRawSource src(drive.string()); });
}
std::string OpenOdometry(const fs::path& seq) {
  return InputErrorMessage([&] { KittiOdometrySource src(seq.string()); });
}
std::string At(const fs::path& file, int line) { return file.string() + ":" + std::to_string(line) + ": "; }

class RawBadInput : public ::testing::Test {
 protected:
  RawBadInput()
      : tmp_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        drive_(testing::MakeRawCopy(tmp_.path(), kFrames)),
        cam_to_cam_(drive_.parent_path() / "calib_cam_to_cam.txt") {}
  testing::TempDir tmp_;
  fs::path drive_;
  fs::path cam_to_cam_;
};

TEST_F(RawBadInput, TheUneditedCopyLoads) {
  const KittiRawSource src(drive_.string());
  EXPECT_EQ(src.size(), kFrames);
  EXPECT_TRUE(src.GroundTruth().has_value());
  EXPECT_TRUE(src.ObjectBoxes().empty());
}

TEST_F(RawBadInput, CalibrationInTheDriveFolderIsFoundToo) {
  for (const char* f : {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"})
    fs::rename(drive_.parent_path() / f, drive_ / f);
  EXPECT_EQ(KittiRawSource(drive_.string()).size(), kFrames);
}

TEST_F(RawBadInput, MissingCalibration) {
  fs::remove(cam_to_cam_);
  EXPECT_THAT(OpenRaw(drive_), AllOf(HasSubstr("calib_cam_to_cam.txt"),
                                     HasSubstr("in the drive's parent folder or the drive folder")));
}

TEST_F(RawBadInput, UnreadableCalibration) {
  fs::remove(cam_to_cam_);
  fs::create_directory(cam_to_cam_);  // a folder where the file should be (tests run as root)
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(cam_to_cam_.string() + ": cannot open the calibration file"));
}

TEST_F(RawBadInput, MissingImuToVeloWhenOxtsIsPresent) {
  fs::remove(drive_.parent_path() / "calib_imu_to_velo.txt");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr("calib_imu_to_velo.txt"));
}

TEST_F(RawBadInput, NonNumericValueInCalibration) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_01:");
  ReplaceLine(cam_to_cam_, "P_rect_01:", "P_rect_01: 7.215377e+02 0 6.095593e+02 abc 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  EXPECT_THAT(OpenRaw(drive_),
              HasSubstr(At(cam_to_cam_, line) + "'P_rect_01' field 4: expected a finite number, got 'abc'"));
}

TEST_F(RawBadInput, WrongCountOfNumbersInCalibration) {
  const int line = LineStartingWith(cam_to_cam_, "R_rect_00:");
  ReplaceLine(cam_to_cam_, "R_rect_00:", "R_rect_00: 1 0 0 0 1 0 0 0");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(cam_to_cam_, line) + "'R_rect_00': expected 9 numbers, got 8"));
}

TEST_F(RawBadInput, MalformedRigidCalibration) {
  const fs::path velo = drive_.parent_path() / "calib_velo_to_cam.txt";
  ReplaceLine(velo, "T:", "T: 1 2");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(velo, 3) + "'T': expected 3 numbers, got 2"));
  ReplaceLine(velo, "T:", "T: 0 0 0");
  ReplaceLine(velo, "R:", "R: 2 0 0 0 1 0 0 0 1");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(velo, 2) + "'R': expected a rotation matrix"));
}

TEST_F(RawBadInput, ZeroFocalLength) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_00:");
  ReplaceLine(cam_to_cam_, "P_rect_00:", "P_rect_00: 0 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  EXPECT_THAT(OpenRaw(drive_),
              HasSubstr(At(cam_to_cam_, line) + "'P_rect_00': expected positive focal lengths"));
}

TEST_F(RawBadInput, NegativeBaseline) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_01:");
  ReplaceLine(cam_to_cam_, "P_rect_01:", "P_rect_01: 7.215377e+02 0 6.095593e+02 3.875744e+02 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  EXPECT_THAT(OpenRaw(drive_),
              HasSubstr(At(cam_to_cam_, line) + "'P_rect_01': expected a positive baseline"));
}

TEST_F(RawBadInput, MissingImageFolder) {
  fs::remove_all(drive_ / "image_01" / "data");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr((drive_ / "image_01" / "data").string() +
                                         ": expected an image folder; it is missing"));
}

TEST_F(RawBadInput, EmptyImageFolder) {
  for (const auto& e : fs::directory_iterator(drive_ / "image_00" / "data")) fs::remove(e.path());
  EXPECT_THAT(OpenRaw(drive_), HasSubstr((drive_ / "image_00" / "data").string() +
                                         ": expected *.png images; the folder has none"));
}

TEST_F(RawBadInput, UnequalLeftAndRightCounts) {
  fs::remove(drive_ / "image_01" / "data" / "0000000004.png");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr((drive_ / "image_01" / "data").string() +
                                         ": expected as many right images as left images"));
}

TEST_F(RawBadInput, LeftAndRightNamesDoNotPair) {
  fs::rename(drive_ / "image_01" / "data" / "0000000004.png", drive_ / "image_01" / "data" / "0000000009.png");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr("0000000009.png: expected the right image 0000000004.png"));
}

TEST_F(RawBadInput, LeftAndRightOfDifferentSizes) {
  const fs::path right = drive_ / "image_01" / "data" / "0000000002.png";
  fs::remove(right);
  cv::imwrite(right.string(), cv::Mat(50, 100, CV_8UC1, cv::Scalar(128)));
  const KittiRawSource src(drive_.string());  // frame 0 is fine
  EXPECT_THAT(InputErrorMessage([&] { src.Load(2); }),
              HasSubstr(right.string() + ": expected a 1242x375 image, got 100x50"));
  EXPECT_NO_THROW(src.Load(1));
}

TEST_F(RawBadInput, CorruptPng) {
  const fs::path left = drive_ / "image_00" / "data" / "0000000003.png";
  // Real PNG header, garbage after it.
  const std::string head = testing::ReadText(testing::RawDriveDir() / "image_00" / "data" / "0000000003.png").substr(0, 64);
  testing::WriteText(left, head + std::string(500, '\x5a'));
  const KittiRawSource src(drive_.string());
  EXPECT_THAT(InputErrorMessage([&] { src.Load(3); }), HasSubstr(left.string() + ": cannot decode the image"));
  testing::WriteText(left, "not a png at all");
  EXPECT_THAT(InputErrorMessage([&] { src.Load(3); }), HasSubstr(left.string() + ": cannot decode the image"));
  fs::remove(left);
  EXPECT_THAT(InputErrorMessage([&] { src.Load(3); }), HasSubstr(left.string() + ": expected an image file; it is missing"));
}

TEST_F(RawBadInput, TimestampsNotIncreasing) {
  const fs::path times = drive_ / "image_00" / "timestamps.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  std::swap(lines[1], lines[2]);
  testing::WriteText(times, testing::JoinLines(lines));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(times, 3) + "expected increasing timestamps"));
}

TEST_F(RawBadInput, MalformedTimestampLine) {
  const fs::path times = drive_ / "image_00" / "timestamps.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  lines[3] = "2011-09-26 13:04:nan";
  testing::WriteText(times, testing::JoinLines(lines));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(times, 4) + "expected a timestamp 'YYYY-MM-DD HH:MM:SS.nnnnnnnnn'"));
}

TEST_F(RawBadInput, TimestampCountDiffersFromImages) {
  const fs::path times = drive_ / "image_00" / "timestamps.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  lines.pop_back();
  testing::WriteText(times, testing::JoinLines(lines));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(times.string() + ": expected one timestamp per image (5), got 4"));
}

TEST_F(RawBadInput, OxtsPacketWithMissingFields) {
  const fs::path packet = drive_ / "oxts" / "data" / "0000000002.txt";
  std::string text = testing::ReadText(packet);
  text = text.substr(0, text.rfind(' '));  // drop the last field
  testing::WriteText(packet, text);
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(packet, 1) + "expected 30 numbers (see dataformat.txt), got 29"));
}

TEST_F(RawBadInput, OxtsPacketWithNaN) {
  const fs::path packet = drive_ / "oxts" / "data" / "0000000001.txt";
  std::istringstream s(testing::ReadText(packet));
  std::vector<std::string> fields{std::istream_iterator<std::string>(s), {}};
  fields[3] = "nan";
  std::string text;
  for (const auto& f : fields) text += f + " ";
  testing::WriteText(packet, text + "\n");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(packet, 1) + "field 4: expected a finite number, got 'nan'"));
}

TEST_F(RawBadInput, OxtsCountDiffersFromImages) {
  fs::remove(drive_ / "oxts" / "data" / "0000000004.txt");
  EXPECT_THAT(OpenRaw(drive_), HasSubstr("expected one OXTS packet per image (5), got 4"));
}

// A valid label file for the 5-frame copy: one car over frames 1..3.
std::string Labels(const std::string& h = "1.5", const std::string& tx = "10.0", int count = 3,
                   int first_frame = 1, bool close_root = true) {
  std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"yes\" ?>\n<!DOCTYPE boost_serialization>\n"
      "<boost_serialization signature=\"serialization::archive\" version=\"9\">\n"
      "<tracklets class_id=\"0\" tracking_level=\"0\" version=\"0\">\n<count>1</count>\n"
      "<item_version>1</item_version>\n<item class_id=\"1\" tracking_level=\"0\" version=\"1\">\n"
      "<objectType>Car</objectType>\n<h>" + h + "</h>\n<w>1.6</w>\n<l>3.9</l>\n"
      "<first_frame>" + std::to_string(first_frame) + "</first_frame>\n<poses class_id=\"2\">\n<count>" +
      std::to_string(count) + "</count>\n";
  for (int k = 0; k < 3; ++k)
    xml += "<item><tx>" + tx + "</tx><ty>2.0</ty><tz>-1.7</tz><rx>0</rx><ry>0</ry><rz>0.5</rz><state>1</state></item>\n";
  xml += "</poses>\n</item>\n</tracklets>\n";
  if (close_root) xml += "</boost_serialization>\n";
  return xml;
}

TEST_F(RawBadInput, ValidHandWrittenLabelsLoad) {
  testing::WriteText(drive_ / "tracklet_labels.xml", Labels());
  const KittiRawSource src(drive_.string());
  const auto boxes = src.ObjectBoxes();
  ASSERT_EQ(boxes.size(), 5u);
  EXPECT_TRUE(boxes[0].empty());
  ASSERT_EQ(boxes[1].size(), 1u);
  EXPECT_EQ(boxes[1][0].type, "Car");
  EXPECT_TRUE(boxes[4].empty());
  // The box centre is the velodyne point (10, 2, −1.7) seen from the camera.
  const Eigen::Vector3d expected = src.cam_from_velo() * Eigen::Vector3d(10.0, 2.0, -1.7);
  EXPECT_LT((boxes[1][0].cam_from_box.translation() - expected).norm(), 1e-12);
}

TEST_F(RawBadInput, MalformedTrackletXml) {
  const fs::path xml = drive_ / "tracklet_labels.xml";
  testing::WriteText(xml, Labels("1.5", "10.0", 3, 1, /*close_root=*/false));
  EXPECT_THAT(OpenRaw(drive_),
              HasSubstr(At(xml, 3) + "malformed XML: the element opened on this line is not closed"));
  testing::WriteText(xml, Labels("tall"));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(xml, 9) + "<h>: expected a finite number, got 'tall'"));
  testing::WriteText(xml, Labels("1.5", "nan"));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(xml, 15) + "<tx>: expected a finite number, got 'nan'"));
  testing::WriteText(xml, Labels("1.5", "10.0", 4));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(xml, 13) + "<poses>: <count> says 4 but 3 <item>s follow"));
  testing::WriteText(xml, Labels("1.5", "10.0", 3, 3));
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(xml, 7) + "object 0: expected frames within [0, 5)"));
  std::string no_l = Labels();
  no_l.replace(no_l.find("<l>3.9</l>"), 10, "");
  testing::WriteText(xml, no_l);
  EXPECT_THAT(OpenRaw(drive_), HasSubstr(At(xml, 7) + "<item> lacks the expected child <l>"));
}

TEST(KittiTracklets, TruncatedRealLabelFileNamesTheFile) {
  testing::TempDir tmp("tracklets_truncated");
  const std::string text = testing::ReadText(testing::RawDriveDir() / "tracklet_labels.xml");
  const fs::path xml = tmp.path() / "tracklet_labels.xml";
  testing::WriteText(xml, text.substr(0, text.size() / 2));
  EXPECT_THAT(InputErrorMessage([&] { ReadTrackletLabels(xml.string(), Pose::Identity(), 154); }),
              AllOf(HasSubstr(xml.string() + ":"), HasSubstr("is not closed")));
}

class OdometryBadInput : public ::testing::Test {
 protected:
  OdometryBadInput()
      : tmp_(::testing::UnitTest::GetInstance()->current_test_info()->name()),
        seq_(testing::MakeOdometryCopy(tmp_.path(), kFrames)),
        calib_(seq_ / "calib.txt") {}
  testing::TempDir tmp_;
  fs::path seq_;
  fs::path calib_;
};

TEST_F(OdometryBadInput, TheUneditedCopyLoads) {
  const KittiOdometrySource src(seq_.string());
  EXPECT_EQ(src.size(), kFrames);
  ASSERT_TRUE(src.GroundTruth().has_value());
  EXPECT_EQ(src.GroundTruth()->size(), 5u);
}

TEST_F(OdometryBadInput, MissingCalibration) {
  fs::remove(calib_);
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(calib_.string() + ": cannot open the calibration file"));
}

TEST_F(OdometryBadInput, MissingP1) {
  auto lines = testing::Lines(testing::ReadText(calib_));
  testing::WriteText(calib_, lines[0] + "\n");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(calib_.string() + ": missing key 'P1:'"));
}

TEST_F(OdometryBadInput, WrongCountOfNumbersInCalibration) {
  ReplaceLine(calib_, "P0:", "P0: 7.07e2 0 6.0e2 0 0 7.07e2 1.8e2 0 0 0 1");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(calib_, 1) + "'P0': expected 12 numbers, got 11"));
}

TEST_F(OdometryBadInput, NonNumericValueInCalibration) {
  ReplaceLine(calib_, "P1:", "P1: 7.07e2 0 6.0e2 -3.8e2 0 7.07e2 1.8e2 0 0 0 one 0");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(calib_, 2) + "'P1' field 11: expected a finite number, got 'one'"));
}

TEST_F(OdometryBadInput, ZeroBaseline) {
  ReplaceLine(calib_, "P1:", "P1: 7.070912e+02 0 6.018873e+02 0 0 7.070912e+02 1.831104e+02 0 0 0 1 0");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(calib_, 2) + "'P1': expected a positive baseline"));
}

TEST_F(OdometryBadInput, NegativeFocalLength) {
  ReplaceLine(calib_, "P0:", "P0: 7.070912e+02 0 6.018873e+02 0 0 -7.070912e+02 1.831104e+02 0 0 0 1 0");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(calib_, 1) + "'P0': expected positive focal lengths"));
}

TEST_F(OdometryBadInput, NaNTimestamp) {
  const fs::path times = seq_ / "times.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  lines[2] = "nan";
  testing::WriteText(times, testing::JoinLines(lines));
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(times, 3) + "expected one finite number of seconds, got 'nan'"));
}

TEST_F(OdometryBadInput, TimestampsNotIncreasing) {
  const fs::path times = seq_ / "times.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  lines[4] = lines[3];
  testing::WriteText(times, testing::JoinLines(lines));
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(times, 5) + "expected increasing timestamps"));
}

TEST_F(OdometryBadInput, UnequalLeftAndRightCounts) {
  fs::remove(seq_ / "image_0" / "000004.png");
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr((seq_ / "image_1").string() + ": expected as many right images"));
}

TEST_F(OdometryBadInput, MalformedPoseLine) {
  const fs::path poses = tmp_.path() / "poses" / "clip_a.txt";
  auto lines = testing::Lines(testing::ReadText(poses));
  lines[3] = "1 0 0 0 0 1 0 0 0 0 1";
  testing::WriteText(poses, testing::JoinLines(lines));
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(At(poses, 4) + "expected 12 numbers (row-major 3x4 pose), got 11"));
}

TEST_F(OdometryBadInput, PoseCountDiffersFromImages) {
  const fs::path poses = tmp_.path() / "poses" / "clip_a.txt";
  auto lines = testing::Lines(testing::ReadText(poses));
  lines.pop_back();
  testing::WriteText(poses, testing::JoinLines(lines));
  EXPECT_THAT(OpenOdometry(seq_), HasSubstr(poses.string() + ": expected one pose per frame (5), got 4"));
}

TEST_F(OdometryBadInput, NoPosesFileMeansNoGroundTruth) {
  fs::remove(tmp_.path() / "poses" / "clip_a.txt");
  EXPECT_FALSE(KittiOdometrySource(seq_.string()).GroundTruth().has_value());
}

TEST(DatasetBadInput, EmptyFolderIsNoneOfTheKnownKinds) {
  testing::TempDir tmp("empty_dataset");
  EXPECT_THAT(InputErrorMessage([&] { OpenStereoSource(tmp.path().string()); }),
              AllOf(HasSubstr(tmp.path().string() + ": is none of the known kinds"),
                    HasSubstr("KITTI raw drive folder (image_00/")));
}

TEST(DatasetBadInput, FolderOfAnotherKindIsRejected) {
  testing::TempDir tmp("other_dataset");
  testing::WriteText(tmp.path() / "mav0" / "cam0" / "data.csv", "#timestamp,filename\n");
  // image_0 without calib.txt is not an odometry sequence either.
  fs::create_directories(tmp.path() / "image_0");
  EXPECT_THAT(InputErrorMessage([&] { OpenStereoSource(tmp.path().string()); }),
              HasSubstr("is none of the known kinds"));
}

TEST(DatasetBadInput, MissingPath) {
  EXPECT_THAT(InputErrorMessage([] { OpenStereoSource("/nonexistent/cslam/drive"); }),
              HasSubstr("/nonexistent/cslam/drive: expected a dataset folder; it does not exist"));
}

}  // namespace
}  // namespace cslam
