// A user's own rig through the built `cslam` (docs/own_rig.md): a KITTI drive re-laid as a
// plain folder with an OpenCV calibration runs to the same trajectories as the KITTI reader,
// the shared EuRoC clip runs with its ground truth and writes what it understood, and
// `cslam calib check` passes a good rig and refuses a bad one with its hint.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>

#include "core/errors.h"
#include "system/datasets/kitti_raw_reader.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadText;
using testing::WriteText;

fs::path Drive0009() { return testing::RawDateDir() / "2011_09_26_drive_0009_sync"; }
fs::path Euroc() { return testing::SharedData() / "euroc" / "V1_01_easy_first50"; }

std::string Exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

class CliOwnRig : public ::testing::Test {
 protected:
  CliOwnRig() : tmp_(std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()) {}
  testing::ProcessResult Cslam(std::vector<std::string> args) {
    args.insert(args.begin(), CSLAM_BINARY);
    return testing::RunProcess(args, tmp_.path() / "logs");
  }
  testing::TempDir tmp_;
};

// The first frames of drive 0009 (no object labels, so nothing but the reader differs) as
// left/, right/ and times.txt, with the KITTI reader's own camera written as an OpenCV stereo
// calibration to the last digit.
fs::path RelayAsPlainFolder(const fs::path& root, int frames, fs::path* calib) {
  const KittiRawSource kitti(Drive0009().string());
  const fs::path dir = root / "relaid";
  std::string times;
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.png", i);
    fs::create_directories(dir / "left");
    fs::create_directories(dir / "right");
    fs::create_symlink(Drive0009() / "image_00" / "data" / name, dir / "left" / name);
    fs::create_symlink(Drive0009() / "image_01" / "data" / name, dir / "right" / name);
    times += Exact(kitti.timestamps()[static_cast<size_t>(i)]) + "\n";
  }
  WriteText(dir / "times.txt", times);
  const StereoCamera& c = kitti.camera();
  const std::string k = "[" + Exact(c.fx) + ", 0, " + Exact(c.cx) + ", 0, " + Exact(c.fy) + ", " + Exact(c.cy) + ", 0, 0, 1]";
  *calib = root / "kitti_stereo.yml";
  WriteText(*calib, "%YAML:1.0\n---\nimage_width: " + std::to_string(c.width) + "\nimage_height: " +
                        std::to_string(c.height) + "\nunit: m\n" +
                        "M1: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: " + k + "\n" +
                        "D1: !!opencv-matrix\n  rows: 1\n  cols: 5\n  dt: d\n  data: [0, 0, 0, 0, 0]\n" +
                        "M2: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: " + k + "\n" +
                        "D2: !!opencv-matrix\n  rows: 1\n  cols: 5\n  dt: d\n  data: [0, 0, 0, 0, 0]\n" +
                        "R: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n" +
                        "T: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: d\n  data: [" + Exact(-c.baseline) + ", 0, 0]\n");
  return dir;
}

TEST_F(CliOwnRig, AKittiDriveReLaidAsAPlainFolderGivesByteIdenticalTrajectories) {
  constexpr int kFrames = 20;
  fs::path calib;
  const fs::path folder = RelayAsPlainFolder(tmp_.path(), kFrames, &calib);
  const fs::path a = tmp_.path() / "kitti", b = tmp_.path() / "plain";
  const std::string frames = std::to_string(kFrames);
  const auto ra = Cslam({"run", Drive0009().string(), "--out", a.string(), "--max-frames", frames,
                         "--sequential", "--no-progress", "--snapshots-every", "0", "--overlays-every", "0"});
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  const auto rb = Cslam({"run", folder.string(), "--calib", calib.string(), "--config",
                         std::string(CSLAM_CONFIGS_DIR) + "/kitti_raw.yaml", "--out", b.string(), "--sequential",
                         "--no-progress", "--snapshots-every", "0", "--overlays-every", "0"});
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  EXPECT_EQ(ReadText(a / "camera_trajectory.txt"), ReadText(b / "camera_trajectory.txt"));
  EXPECT_EQ(ReadText(a / "camera_trajectory.tum"), ReadText(b / "camera_trajectory.tum"));
  EXPECT_EQ(ReadText(a / "clusters.csv"), ReadText(b / "clusters.csv"));
  EXPECT_EQ(testing::Lines(ReadText(a / "camera_trajectory.txt")).size(), static_cast<size_t>(kFrames));
  EXPECT_THAT(ReadText(b / "rectified.yaml"), HasSubstr("baseline: 0.5"));
}

TEST_F(CliOwnRig, TheEurocClipRunsWithItsGroundTruthAndTheCameraHardlyMoves) {
  const fs::path out = tmp_.path() / "out";
  const auto r = Cslam({"run", Euroc().string(), "--gt", (Euroc() / "groundtruth_tum.txt").string(), "--out",
                        out.string(), "--no-progress", "--snapshots-every", "0", "--overlays-every", "0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"rig.yaml", "rectified.yaml", "camera_trajectory.txt", "camera_trajectory_gt.txt", "metrics.json"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  // Path lengths of the estimate and the ground truth over the 50 frames, from the files.
  for (const char* f : {"camera_trajectory.txt", "camera_trajectory_gt.txt"}) {
    double len = 0;
    std::vector<double> prev;
    for (const auto& line : testing::Lines(ReadText(out / f))) {
      std::istringstream s(line);
      std::vector<double> v{std::istream_iterator<double>(s), {}};
      ASSERT_EQ(v.size(), 12u);
      if (!prev.empty()) len += std::hypot(v[3] - prev[3], v[7] - prev[7], v[11] - prev[11]);
      prev = v;
    }
    EXPECT_LT(len, 0.02) << f;
  }
  EXPECT_THAT(ReadText(out / "rig.yaml"), HasSubstr("T_cn_cnm1"));
}

TEST_F(CliOwnRig, CalibCheckPassesEurocAndWritesThePicture) {
  const fs::path out = tmp_.path() / "check";
  const auto r = Cslam({"calib", "check", Euroc().string(), "--out", out.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("rectified: median 0."));
  EXPECT_THAT(r.out, HasSubstr("baseline                    0.1101 m"));
  EXPECT_TRUE(fs::exists(out / "calib_check.png"));
}

TEST_F(CliOwnRig, AnInvertedTIsRefusedByRunAndByCalibCheckWithTheHint) {
  fs::path calib;
  const fs::path folder = RelayAsPlainFolder(tmp_.path(), 3, &calib);
  std::string text = ReadText(calib);
  text.replace(text.find("data: [-"), 8, "data: [");
  WriteText(calib, text);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", folder.string(), "--calib", calib.string(), "--out", (tmp_.path() / "o").string()},
        std::vector<std::string>{"calib", "check", folder.string(), "--calib", calib.string(), "--out",
                                 (tmp_.path() / "o").string()}}) {
    const auto r = Cslam(args);
    EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
    EXPECT_THAT(r.err, HasSubstr(calib.string() + ": T looks inverted: Kalibr's T_cn_cnm1 maps cam0 to cam1"));
    EXPECT_FALSE(fs::exists(tmp_.path() / "o"));
  }
}

TEST_F(CliOwnRig, ACalibrationInMillimetresIsRefusedByRun) {
  fs::path calib;
  const fs::path folder = RelayAsPlainFolder(tmp_.path(), 3, &calib);
  testing::ReplaceLine(calib, "unit:", "unit: mm");
  std::string text = ReadText(calib);
  WriteText(calib, text);
  // A baseline of 0.54 "mm" is 0.00054 m: below the range too.
  const auto r = Cslam({"run", folder.string(), "--calib", calib.string(), "--out", (tmp_.path() / "o").string()});
  EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("expected 0.01-2 m for a stereo rig"));
}

TEST_F(CliOwnRig, ABlankFirstPairIsNotRefusedByRunButCalibCheckCannotMeasureIt) {
  const fs::path folder = tmp_.path() / "blank";
  const cv::Mat black(48, 64, CV_8UC1, cv::Scalar(0));
  for (const char* side : {"left", "right"}) {
    fs::create_directories(folder / side);
    for (int i = 0; i < 3; ++i) cv::imwrite((folder / side / ("00000" + std::to_string(i) + ".png")).string(), black);
  }
  WriteText(tmp_.path() / "camchain.yaml", R"(cam0:
  camera_model: pinhole
  intrinsics: [50, 50, 32, 24]
  distortion_model: radtan
  distortion_coeffs: [-0.1, 0.01, 0, 0]
  resolution: [64, 48]
cam1:
  T_cn_cnm1: [[1, 0, 0, -0.12], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
  camera_model: pinhole
  intrinsics: [50, 50, 32, 24]
  distortion_model: radtan
  distortion_coeffs: [-0.1, 0.01, 0, 0]
  resolution: [64, 48]
)");
  const std::string calib = (tmp_.path() / "camchain.yaml").string();
  const auto run = Cslam({"run", folder.string(), "--calib", calib, "--out", (tmp_.path() / "o").string(), "--no-progress"});
  EXPECT_NE(run.exit_code, kExitInputError) << run.err;
  EXPECT_THAT(run.err, HasSubstr("the rig's rows could not be checked on the first pair"));
  const auto check = Cslam({"calib", "check", folder.string(), "--calib", calib, "--out", (tmp_.path() / "c").string()});
  EXPECT_EQ(check.exit_code, kExitInputError);
  EXPECT_THAT(check.err, HasSubstr("only 0 stereo matches in the checked pairs; expected at least 20"));
}

}  // namespace
}  // namespace cslam
