// Snapshots and overlays written during a `cslam run` (--snapshots-every, --overlays-every) on
// a small rendered synthetic sequence: one picture per due frame, showing the clustered
// landmarks and the tracked keypoints.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "system/draw/cluster_colors.h"
#include "tests/apps/subprocess.h"
#include "tests/system/image_test_util.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

class CliFrameRenders : public ::testing::Test {
 protected:
  static constexpr int kFrames = 20;
  CliFrameRenders() : tmp_("cli_frame_renders") {
    const auto synth = testing::RunProcess(
        {CSLAM_BINARY, "synth", "--preset", "outdoor", "--seed", "4", "--frames",
         std::to_string(kFrames), "--landmark-density", "0.3", "--images", "--out", seq().string()},
        tmp_.path() / "synth_logs");
    EXPECT_EQ(synth.exit_code, 0) << synth.err;
  }
  fs::path seq() const { return tmp_.path() / "seq"; }
  fs::path out() const { return tmp_.path() / "out"; }
  testing::ProcessResult Run(const std::vector<std::string>& extra) {
    std::vector<std::string> args = {CSLAM_BINARY, "run", seq().string(), "--out", out().string(),
                                     "--no-progress"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunProcess(args, tmp_.path() / "run_logs");
  }
  static std::string Numbered(const char* stem, int frame) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%06d.png", stem, frame);
    return name;
  }
  testing::TempDir tmp_;
};

TEST_F(CliFrameRenders, EveryDueFrameGetsASnapshotAndAnOverlayShowingItsPoints) {
  const auto r = Run({"--snapshots-every", "5", "--overlays-every", "5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int f : {4, 9, 14, 19}) {
    const cv::Mat snapshot = cv::imread((out() / "render" / Numbered("snapshot", f)).string());
    const cv::Mat overlay = cv::imread((out() / "render" / Numbered("overlay", f)).string());
    ASSERT_FALSE(snapshot.empty()) << f;
    ASSERT_FALSE(overlay.empty()) << f;
    // The static landmarks are drawn as dots in the static colour.
    EXPECT_GT(testing::CountColour(snapshot, BgrForCluster(0), 10), 200) << f;
    // The overlay is the left image with keypoints and trails drawn over it.
    char left[32];
    std::snprintf(left, sizeof left, "%06d.png", f);
    const cv::Mat image = cv::imread((seq() / "sequences" / "00" / "image_0" / left).string());
    ASSERT_EQ(image.size(), overlay.size());
    cv::Mat diff;
    cv::absdiff(image, overlay, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(diff > 30), 1000) << f;
  }
  // Not due: no picture.
  EXPECT_FALSE(fs::exists(out() / "render" / Numbered("snapshot", 5)));
  EXPECT_FALSE(fs::exists(out() / "render" / Numbered("overlay", 3)));
}

TEST_F(CliFrameRenders, ZeroTurnsThePicturesOff) {
  const auto r = Run({"--snapshots-every", "0", "--overlays-every", "0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const auto& entry : fs::directory_iterator(out() / "render")) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.rfind("snapshot_", 0), std::string::npos) << name;
    EXPECT_EQ(name.rfind("overlay_", 0), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace cslam
