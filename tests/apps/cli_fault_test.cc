// docs/reliability.md, "Faults": `cslam run` interrupted by SIGINT / SIGTERM, and a run through
// black frames. The program runs as a child process, as a user would run it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

/// Every non-comment line of `file` as numbers; fails the test on a line of the wrong width.
std::vector<std::vector<double>> ReadRows(const fs::path& file, size_t width) {
  std::vector<std::vector<double>> rows;
  for (const auto& line : testing::Lines(testing::ReadText(file))) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::vector<double> v{std::istream_iterator<double>(s), {}};
    EXPECT_EQ(v.size(), width) << file << ": " << line;
    for (double x : v) EXPECT_TRUE(std::isfinite(x)) << file << ": " << line;
    rows.push_back(v);
  }
  return rows;
}

class CliSignal : public ::testing::TestWithParam<int> {
 protected:
  static constexpr int kFrames = 300;
  CliSignal() : tmp_(std::string("cli_signal_") + std::to_string(GetParam())) {
    const auto synth = testing::RunProcess(
        {CSLAM_BINARY, "synth", "--preset", "outdoor", "--seed", "4", "--frames", std::to_string(kFrames),
         "--landmark-density", "0.3", "--out", (tmp_.path() / "seq").string()},
        tmp_.path() / "synth_logs");
    EXPECT_EQ(synth.exit_code, 0) << synth.err;
    // One clustering iteration per window: the signal path is what is tested, and the run
    // must also be quick under the sanitizers.
    testing::WriteText(tmp_.path() / "config.yaml", "backend:\n  max_iterations: 1\n");
  }
  testing::TempDir tmp_;
};

TEST_P(CliSignal, StopsWritesValidOutputsAndExitsWithTheSignalsCode) {
  const int sig = GetParam();
  const fs::path out = tmp_.path() / "out";
  bool saw_window = false;
  const auto r = testing::RunProcess(
      {CSLAM_BINARY, "run", (tmp_.path() / "seq").string(), "--out", out.string(), "--mode", "online",
       "--config", (tmp_.path() / "config.yaml").string(), "--no-progress", "-v"},  // -v: the window log
      tmp_.path() / "logs", [&](pid_t pid, const fs::path& err) {
        // Signal once a window is in the map, so there is something to write.
        saw_window = testing::WaitForText(err, "window 0..29 integrated", std::chrono::seconds(600));
        kill(pid, sig);
      });
  ASSERT_TRUE(saw_window) << r.err;
  EXPECT_FALSE(r.signalled) << "killed by the signal instead of stopping cleanly\n" << r.err;
  EXPECT_EQ(r.exit_code, sig == SIGINT ? kExitSigint : kExitSigterm) << r.err;
  EXPECT_THAT(r.err, HasSubstr("stopping"));
  EXPECT_THAT(testing::TemporaryFilesUnder(out), IsEmpty());
  const auto kitti = ReadRows(out / "camera_trajectory.txt", 12);
  const auto tum = ReadRows(out / "camera_trajectory.tum", 8);
  EXPECT_GE(kitti.size(), 30u);
  EXPECT_LT(kitti.size(), static_cast<size_t>(kFrames)) << "the run was not interrupted";
  EXPECT_EQ(tum.size(), kitti.size());
  for (const char* f : {"clusters.csv", "metrics.json", "run.log", "objects/index.csv"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  EXPECT_THAT(testing::ReadText(out / "metrics.json"), HasSubstr("\"interrupted\": true"));
}

INSTANTIATE_TEST_SUITE_P(SigintAndSigterm, CliSignal, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto& info) { return info.param == SIGINT ? "Sigint" : "Sigterm"; });

TEST(CliTrackingLoss, BlackFramesLeaveAMarkedGapAndTheTrajectoryContinues) {
  testing::TempDir tmp("cli_black_frames");
  constexpr int kFrames = 16;
  const fs::path seq = testing::MakeOdometryCopy(tmp.path() / "data", kFrames);
  // Frames 7 and 8 are black in both cameras.
  const cv::Mat first = cv::imread((seq / "image_0" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(first.empty());
  for (const char* cam : {"image_0", "image_1"})
    for (const char* name : {"000007.png", "000008.png"}) {
      fs::remove(seq / cam / name);
      cv::imwrite((seq / cam / name).string(), cv::Mat(first.size(), CV_8UC1, cv::Scalar(0)));
    }
  testing::WriteText(tmp.path() / "config.yaml", "online:\n  window_frames: 6\n  window_every: 2\n");
  const fs::path out = tmp.path() / "out";
  const auto r = testing::RunProcess({CSLAM_BINARY, "run", seq.string(), "--out", out.string(), "--config",
                                      (tmp.path() / "config.yaml").string(), "--no-progress"},
                                     tmp.path() / "logs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("frame 7: tracking lost"));
  // The frames with a pose: all but the black ones; the gap is written down.
  std::vector<int> frames;
  bool gap_noted = false;
  for (const auto& line : testing::Lines(testing::ReadText(out / "camera_trajectory_frames.txt"))) {
    if (line.rfind("# gap", 0) == 0) gap_noted = line.find("at frame 9") != std::string::npos;
    if (!line.empty() && line[0] != '#') frames.push_back(std::stoi(line));
  }
  std::vector<int> expected;
  for (int f = 0; f < kFrames; ++f)
    if (f != 7 && f != 8) expected.push_back(f);
  EXPECT_EQ(frames, expected);
  EXPECT_TRUE(gap_noted) << testing::ReadText(out / "camera_trajectory_frames.txt");
  EXPECT_EQ(ReadRows(out / "camera_trajectory.txt", 12).size(), expected.size());
}

/// A 40-frame outdoor synthetic sequence under `dir`; empty (and a test failure) if synth fails.
fs::path SmallOutdoorSequence(const fs::path& dir) {
  const fs::path seq = dir / "seq";
  const auto synth = testing::RunProcess(
      {CSLAM_BINARY, "synth", "--preset", "outdoor", "--seed", "4", "--frames", "40",
       "--landmark-density", "0.3", "--out", seq.string()},
      dir / "synth_logs");
  EXPECT_EQ(synth.exit_code, 0) << synth.err;
  return synth.exit_code == 0 ? seq : fs::path();
}

TEST(CliNoEstimate, EveryWindowDiscardedWritesTheOutputsAndExitsFive) {
  testing::TempDir tmp("cli_no_estimate");
  const fs::path seq = SmallOutdoorSequence(tmp.path());
  ASSERT_FALSE(seq.empty());
  // A sanity bound no real camera step meets: the one batch window is discarded.
  testing::WriteText(tmp.path() / "config.yaml",
                     "backend:\n  max_iterations: 1\nsanity:\n  max_step_depths: 1.0e-9\n");
  const fs::path out = tmp.path() / "out";
  const auto r = testing::RunProcess({CSLAM_BINARY, "run", seq.string(), "--out", out.string(),
                                      "--mode", "batch", "--config",
                                      (tmp.path() / "config.yaml").string(), "--no-progress"},
                                     tmp.path() / "logs");
  EXPECT_EQ(r.exit_code, kExitNoEstimate) << r.err;
  EXPECT_THAT(r.err, HasSubstr("no usable estimate"));
  EXPECT_THAT(r.err, HasSubstr("no estimate: all 1 backend window(s) were discarded"));
  EXPECT_THAT(testing::TemporaryFilesUnder(out), IsEmpty());
  for (const char* f : {"metrics.json", "run.log", "clusters.csv", "camera_trajectory.txt"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  const std::string metrics = testing::ReadText(out / "metrics.json");
  EXPECT_THAT(metrics, HasSubstr("\"failed_windows\""));
  EXPECT_THAT(metrics, ::testing::Not(HasSubstr("\"failed_windows\": []")));
}

TEST(CliNoEstimate, ARunWithAUsableWindowExitsZero) {
  testing::TempDir tmp("cli_some_estimate");
  const fs::path seq = SmallOutdoorSequence(tmp.path());
  ASSERT_FALSE(seq.empty());
  testing::WriteText(tmp.path() / "config.yaml", "backend:\n  max_iterations: 1\n");
  const auto r = testing::RunProcess({CSLAM_BINARY, "run", seq.string(), "--out",
                                      (tmp.path() / "out").string(), "--mode", "batch", "--config",
                                      (tmp.path() / "config.yaml").string(), "--no-progress"},
                                     tmp.path() / "logs");
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("no estimate")));
}

}  // namespace
}  // namespace cslam
