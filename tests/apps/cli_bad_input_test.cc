// docs/reliability.md, "Bad input": one test per row. Each runs the built `cslam` program on a
// small edited copy of real (or generated) data and checks what a user gets: the documented
// exit code, a message naming the file (and line or key) and what was expected, no crash, and
// no half-written output (no output folder when the input is rejected up front; only complete
// files, no temporaries, when a run stops part-way).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;
using testing::LineStartingWith;
using testing::ReplaceLine;

constexpr int kFrames = 5;

std::string At(const fs::path& file, int line) { return file.string() + ":" + std::to_string(line) + ": "; }

class CliBadInput : public ::testing::Test {
 protected:
  CliBadInput() : tmp_(std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()) {}

  /// `cslam run INPUT --out OUT [extra...]`.
  testing::ProcessResult Run(const fs::path& input, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {CSLAM_BINARY, "run", input.string(), "--out", out().string(),
                                     "--no-progress"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunProcess(args, tmp_.path() / "logs");
  }
  fs::path out() const { return tmp_.path() / "out"; }

  /// Rejected before any work: the exit code, the message, and no output folder at all.
  void ExpectRejected(const testing::ProcessResult& r, int code, const std::string& message) {
    EXPECT_FALSE(r.signalled) << r.err;
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_THAT(r.err, Not(HasSubstr("internal error")));
    EXPECT_FALSE(fs::exists(out())) << "an output folder was created for a rejected run";
  }

  /// Stopped part-way: exit 1 with the message, the outputs of the frames before it complete
  /// (the trajectory files exist and every line is a pose) and no temporary file left.
  void ExpectStoppedPartWay(const testing::ProcessResult& r, const std::string& message) {
    EXPECT_FALSE(r.signalled) << r.err;
    EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_THAT(testing::TemporaryFilesUnder(out()), IsEmpty());
    ASSERT_TRUE(fs::exists(out() / "camera_trajectory.txt"));
    for (const auto& line : testing::Lines(testing::ReadText(out() / "camera_trajectory.txt"))) {
      std::istringstream s(line);
      std::vector<double> v{std::istream_iterator<double>(s), {}};
      EXPECT_EQ(v.size(), 12u) << line;
    }
    EXPECT_TRUE(fs::exists(out() / "run.log"));
  }

  testing::TempDir tmp_;
};

class CliRawBadInput : public CliBadInput {
 protected:
  CliRawBadInput()
      : drive_(testing::MakeRawCopy(tmp_.path() / "data", kFrames)),
        cam_to_cam_(drive_.parent_path() / "calib_cam_to_cam.txt") {}
  fs::path drive_;
  fs::path cam_to_cam_;
};

class CliOdometryBadInput : public CliBadInput {
 protected:
  CliOdometryBadInput() : seq_(testing::MakeOdometryCopy(tmp_.path() / "data", kFrames)), calib_(seq_ / "calib.txt") {}
  fs::path seq_;
  fs::path calib_;
};

// --- calibration -------------------------------------------------------------------------

TEST_F(CliRawBadInput, MissingCalibrationFile) {
  fs::remove(cam_to_cam_);
  ExpectRejected(Run(drive_), kExitInputError, "calib_cam_to_cam.txt");
}

TEST_F(CliOdometryBadInput, MissingCalibrationFile) {
  fs::remove(calib_);
  ExpectRejected(Run(seq_), kExitInputError, "image_0/ but no calib.txt");
}

TEST_F(CliRawBadInput, NonNumericCalibrationValue) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_01:");
  ReplaceLine(cam_to_cam_, "P_rect_01:", "P_rect_01: 7.215377e+02 0 6.095593e+02 abc 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  ExpectRejected(Run(drive_), kExitInputError,
                 At(cam_to_cam_, line) + "'P_rect_01' field 4: expected a finite number, got 'abc'");
}

TEST_F(CliOdometryBadInput, WrongCountOfCalibrationNumbers) {
  ReplaceLine(calib_, "P0:", "P0: 7.07e2 0 6.0e2 0 0 7.07e2 1.8e2 0 0 0 1");
  ExpectRejected(Run(seq_), kExitInputError, At(calib_, 1) + "'P0': expected 12 numbers, got 11");
}

TEST_F(CliRawBadInput, ZeroFocalLength) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_00:");
  ReplaceLine(cam_to_cam_, "P_rect_00:", "P_rect_00: 0 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  ExpectRejected(Run(drive_), kExitInputError, At(cam_to_cam_, line) + "'P_rect_00': expected positive focal lengths");
}

TEST_F(CliOdometryBadInput, NegativeFocalLength) {
  ReplaceLine(calib_, "P0:", "P0: 7.070912e+02 0 6.018873e+02 0 0 -7.070912e+02 1.831104e+02 0 0 0 1 0");
  ExpectRejected(Run(seq_), kExitInputError, At(calib_, 1) + "'P0': expected positive focal lengths");
}

TEST_F(CliOdometryBadInput, ZeroBaseline) {
  ReplaceLine(calib_, "P1:", "P1: 7.070912e+02 0 6.018873e+02 0 0 7.070912e+02 1.831104e+02 0 0 0 1 0");
  ExpectRejected(Run(seq_), kExitInputError, At(calib_, 2) + "'P1': expected a positive baseline");
}

TEST_F(CliRawBadInput, NegativeBaseline) {
  const int line = LineStartingWith(cam_to_cam_, "P_rect_01:");
  ReplaceLine(cam_to_cam_, "P_rect_01:", "P_rect_01: 7.215377e+02 0 6.095593e+02 3.875744e+02 0 7.215377e+02 1.728540e+02 0 0 0 1 0");
  ExpectRejected(Run(drive_), kExitInputError, At(cam_to_cam_, line) + "'P_rect_01': expected a positive baseline");
}

// --- images --------------------------------------------------------------------------------

TEST_F(CliRawBadInput, MissingRightImagesAndNoColourPairNamesBothPairs) {
  fs::remove_all(drive_ / "image_01");
  ExpectRejected(Run(drive_), kExitInputError,
                 drive_.string() + ": has no complete stereo pair: expected image_00/data and "
                                   "image_01/data (grey) or image_02/data and image_03/data (colour)");
}

TEST_F(CliOdometryBadInput, UnequalLeftAndRightCounts) {
  fs::remove(seq_ / "image_1" / "000004.png");
  ExpectRejected(Run(seq_), kExitInputError, (seq_ / "image_1").string() + ": expected as many right images");
}

TEST_F(CliRawBadInput, LeftAndRightOfDifferentSizes) {
  const fs::path right = drive_ / "image_01" / "data" / "0000000002.png";
  fs::remove(right);
  cv::imwrite(right.string(), cv::Mat(50, 100, CV_8UC1, cv::Scalar(128)));
  ExpectStoppedPartWay(Run(drive_), right.string() + ": expected a 1242x375 image, got 100x50");
}

TEST_F(CliRawBadInput, CorruptPngInTheMiddle) {
  const fs::path left = drive_ / "image_00" / "data" / "0000000003.png";
  const std::string head = testing::ReadText(testing::RawDriveDir() / "image_00" / "data" / "0000000003.png").substr(0, 64);
  testing::WriteText(left, head + std::string(500, '\x5a'));
  ExpectStoppedPartWay(Run(drive_), left.string() + ": cannot decode the image");
}

TEST_F(CliOdometryBadInput, TruncatedPngInTheMiddle) {
  const fs::path left = seq_ / "image_0" / "000002.png";
  const std::string png = testing::ReadText(testing::OdometrySequenceDir() / "image_0" / "000002.png");
  testing::WriteText(left, png.substr(0, png.size() / 2));
  ExpectStoppedPartWay(Run(seq_), left.string() + ": cannot decode the image");
}

// --- folders --------------------------------------------------------------------------------

TEST_F(CliBadInput, EmptyFolder) {
  fs::create_directories(tmp_.path() / "empty");
  ExpectRejected(Run(tmp_.path() / "empty"), kExitInputError, (tmp_.path() / "empty").string() + ": is none of the known kinds");
}

TEST_F(CliBadInput, UnreadableFolder) {
  // A file where the folder should be (permissions cannot hide a folder from root).
  testing::WriteText(tmp_.path() / "not_a_folder", "x");
  ExpectRejected(Run(tmp_.path() / "not_a_folder"), kExitInputError,
                 (tmp_.path() / "not_a_folder").string() + ": expected a dataset folder; it is a file");
}

TEST_F(CliBadInput, MissingFolder) {
  ExpectRejected(Run(tmp_.path() / "nowhere"), kExitInputError,
                 (tmp_.path() / "nowhere").string() + ": expected a dataset folder; it does not exist");
}

TEST_F(CliRawBadInput, EmptyImageFolder) {
  for (const auto& e : fs::directory_iterator(drive_ / "image_00" / "data")) fs::remove(e.path());
  ExpectRejected(Run(drive_), kExitInputError, (drive_ / "image_00" / "data").string() + ": expected *.png images; the folder has none");
}

TEST_F(CliBadInput, FolderOfNoKnownKind) {
  testing::WriteText(tmp_.path() / "euroc" / "mav0" / "cam0" / "data.csv", "#timestamp,filename\n");
  ExpectRejected(Run(tmp_.path() / "euroc"), kExitInputError,
                 (tmp_.path() / "euroc").string() + ": is none of the known kinds: expected a KITTI raw drive folder");
}

// --- timestamps and OXTS ------------------------------------------------------------------

TEST_F(CliRawBadInput, TimestampsNotIncreasing) {
  const fs::path times = drive_ / "image_00" / "timestamps.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  std::swap(lines[1], lines[2]);
  testing::WriteText(times, testing::JoinLines(lines));
  ExpectRejected(Run(drive_), kExitInputError, At(times, 3) + "expected increasing timestamps");
}

TEST_F(CliOdometryBadInput, NaNTimestamp) {
  const fs::path times = seq_ / "times.txt";
  auto lines = testing::Lines(testing::ReadText(times));
  lines[2] = "nan";
  testing::WriteText(times, testing::JoinLines(lines));
  ExpectRejected(Run(seq_), kExitInputError, At(times, 3) + "expected one finite number of seconds, got 'nan'");
}

TEST_F(CliRawBadInput, OxtsLineWithMissingFields) {
  const fs::path packet = drive_ / "oxts" / "data" / "0000000002.txt";
  std::string text = testing::ReadText(packet);
  testing::WriteText(packet, text.substr(0, text.rfind(' ')));
  ExpectRejected(Run(drive_), kExitInputError, At(packet, 1) + "expected 30 numbers (see dataformat.txt), got 29");
}

TEST_F(CliRawBadInput, OxtsLineWithNaN) {
  const fs::path packet = drive_ / "oxts" / "data" / "0000000001.txt";
  std::istringstream s(testing::ReadText(packet));
  std::vector<std::string> fields{std::istream_iterator<std::string>(s), {}};
  fields[3] = "nan";
  std::string text;
  for (const auto& f : fields) text += f + " ";
  testing::WriteText(packet, text + "\n");
  ExpectRejected(Run(drive_), kExitInputError, At(packet, 1) + "field 4: expected a finite number, got 'nan'");
}

TEST_F(CliRawBadInput, MalformedTrackletXml) {
  const fs::path xml = drive_ / "tracklet_labels.xml";
  const std::string text = testing::ReadText(testing::RawDriveDir() / "tracklet_labels.xml");
  testing::WriteText(xml, text.substr(0, text.size() / 3));
  const auto r = Run(drive_);
  ExpectRejected(r, kExitInputError, xml.string() + ":");
  // Cut mid-file: the element whose closing tag was cut is named by its opening line.
  EXPECT_THAT(r.err, HasSubstr("malformed XML: the element opened on this line"));
}

// --- configuration ------------------------------------------------------------------------

class CliConfig : public CliOdometryBadInput {
 protected:
  testing::ProcessResult RunWithConfig(const std::string& yaml) {
    testing::WriteText(config(), yaml);
    return Run(seq_, {"--config", config().string()});
  }
  fs::path config() const { return tmp_.path() / "config.yaml"; }
};

TEST_F(CliConfig, UnknownKey) {
  const auto r = RunWithConfig("online:\n  window_frame: 20\n");
  ExpectRejected(r, kExitConfigError,
                 config().string() + ":2: online.window_frame: unknown key (known: window_frames,");
}

TEST_F(CliConfig, MisspeltTopLevelKey) {
  const auto r = RunWithConfig("mode: online\npresett: indoor\n");
  ExpectRejected(r, kExitConfigError,
                 config().string() + ":2: presett: unknown key (known: preset, method,");
}

// backend and frontend used to be loaded without the unknown-key check (exit 0).
TEST_F(CliConfig, MisspeltKeyInTheBackendSection) {
  const auto r = RunWithConfig("backend:\n  max_iteration: 3\n");
  ExpectRejected(r, kExitConfigError,
                 config().string() + ":2: backend.max_iteration: unknown key (known: distance,");
  EXPECT_THAT(r.err, HasSubstr("max_iterations"));
}

TEST_F(CliConfig, MisspeltKeyInANestedSection) {
  const auto r = RunWithConfig("frontend:\n  tracker:\n    bogus_key: 1\n");
  ExpectRejected(r, kExitConfigError,
                 config().string() + ":3: frontend.tracker.bogus_key: unknown key (known: window_px,");
}

TEST_F(CliConfig, WrongType) {
  const auto r = RunWithConfig("online:\n  window_frames: many\n");
  ExpectRejected(r, kExitConfigError, config().string() + ":2: online.window_frames");
  EXPECT_THAT(r.err, HasSubstr("many"));
}

TEST_F(CliConfig, OutOfRangeValue) {
  ExpectRejected(RunWithConfig("online:\n  window_frames: 2\n"), kExitConfigError,
                 config().string() + ":2: online.window_frames: must be at least 5 frames, got 2");
}

TEST_F(CliConfig, OutOfRangeValueInANestedSection) {
  ExpectRejected(RunWithConfig("backend:\n  hac:\n    max_dense_items: -1\n"), kExitConfigError,
                 config().string() + ":3: backend.hac.max_dense_items: must be in [0, 16384]");
}

TEST_F(CliConfig, TheAblationIsSpeltAsOnTheCommandLine) {
  ExpectRejected(RunWithConfig("ablation: no_u\n"), kExitConfigError,
                 config().string() + ":1: ablation: must be one of none, no-u, no-i, p2p-icp, got 'no_u'");
}

TEST_F(CliConfig, NiceIncrementOutsideTheKernelsRange) {
  ExpectRejected(RunWithConfig("online:\n  background_nice: 20\n"), kExitConfigError,
                 config().string() + ":2: online.background_nice: must be in [0, 19]");
}

TEST_F(CliConfig, KeyGivenTwice) {
  const auto r = RunWithConfig("online:\n  window_every: 5\nonline:\n  window_every: 7\n");
  ExpectRejected(r, kExitConfigError, config().string() + ":3: online given twice (first on line 1)");
}

TEST_F(CliConfig, NotYaml) {
  ExpectRejected(RunWithConfig("online: [1, 2\n"), kExitConfigError, config().string() + ":2: not valid YAML");
}

// --- output -----------------------------------------------------------------------------------

TEST_F(CliOdometryBadInput, OutputFolderCannotBeWritten) {
  testing::WriteText(tmp_.path() / "a_file", "x");
  const fs::path bad_out = tmp_.path() / "a_file" / "out";
  const auto r = testing::RunProcess({CSLAM_BINARY, "run", seq_.string(), "--out", bad_out.string(), "--no-progress"},
                                     tmp_.path() / "logs");
  EXPECT_FALSE(r.signalled);
  EXPECT_EQ(r.exit_code, kExitOutputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr(bad_out.string() + ": cannot create the output folder"));
}

// --- synthetic observations ---------------------------------------------------------------

class CliSyntheticBadInput : public CliBadInput {
 protected:
  CliSyntheticBadInput() : dir_(tmp_.path() / "synthetic") {
    SyntheticOptions o;
    o.preset = "outdoor";
    o.seed = 5;
    o.frames = 8;
    o.landmark_density = 0.2;
    WriteSynthetic(GenerateSynthetic(o), dir_.string());
  }
  /// Rewrites data line `k` (1-based, after the header) of observations.csv with `edit`.
  int EditObservation(int k, const std::function<void(std::vector<std::string>&)>& edit) {
    const fs::path obs = dir_ / "observations.csv";
    auto lines = testing::Lines(testing::ReadText(obs));
    std::vector<std::string> f;
    std::stringstream s(lines[k]);
    for (std::string x; std::getline(s, x, ',');) f.push_back(x);
    edit(f);
    std::string joined;
    for (const auto& x : f) joined += (joined.empty() ? "" : ",") + x;
    lines[k] = joined;
    testing::WriteText(obs, testing::JoinLines(lines));
    return k + 1;
  }
  fs::path dir_;
};

TEST_F(CliSyntheticBadInput, NegativeDisparity) {
  const int line = EditObservation(3, [](auto& f) { f[4] = std::to_string(std::stod(f[2]) + 5.0); });
  ExpectRejected(Run(dir_), kExitInputError,
                 At(dir_ / "observations.csv", line) + "expected a positive disparity uL - uR");
}

TEST_F(CliSyntheticBadInput, LandmarkBehindTheCamera) {
  // Move a static landmark seen in frame 0 behind that camera (world = the camera at frame 0,
  // looking along +z; static landmarks are stored in the world frame).
  const auto split = [](const std::string& line) {
    std::vector<std::string> f;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, ',');) f.push_back(x);
    return f;
  };
  const fs::path lm = dir_ / "gt_landmarks.csv";
  auto landmarks = testing::Lines(testing::ReadText(lm));
  const auto obs = testing::Lines(testing::ReadText(dir_ / "observations.csv"));
  int line = 0;
  for (size_t k = 1; k < obs.size() && line == 0; ++k) {
    const auto f = split(obs[k]);
    const int landmark = std::stoi(f[1]);
    const auto l = split(landmarks[landmark + 1]);
    if (f[0] != "0" || l[1] != "0") continue;
    landmarks[landmark + 1] = l[0] + "," + l[1] + "," + l[2] + "," + l[3] + ",-50";
    line = static_cast<int>(k) + 1;
  }
  ASSERT_GT(line, 0) << "no static landmark seen in frame 0";
  testing::WriteText(lm, testing::JoinLines(landmarks));
  ExpectRejected(Run(dir_), kExitInputError,
                 At(dir_ / "observations.csv", line) + "the landmark's ground-truth point is behind the camera");
}

}  // namespace
}  // namespace cslam
