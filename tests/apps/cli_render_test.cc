// `cslam render OUT` on the outputs of a real (small) `cslam run`, run as a user would: the
// pictures (trajectory.png, objects.png) come back identical to the run's own, and a missing or
// corrupt output file is named with the documented exit code, leaving the old picture in place.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "system/draw/cluster_colors.h"
#include "system/eval/metrics_json.h"
#include "system/render/trajectory_plot.h"
#include "system/run/object_track_plot.h"
#include "system/run/run_outputs_reader.h"
#include "system/run/run_trajectory_plot.h"
#include "tests/apps/subprocess.h"
#include "tests/system/image_test_util.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

class CliRender : public ::testing::Test {
 protected:
  static constexpr int kFrames = 30;
  CliRender() : tmp_(std::string("cli_render_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    const auto synth = testing::RunProcess(
        {CSLAM_BINARY, "synth", "--preset", "outdoor", "--seed", "4", "--frames", std::to_string(kFrames),
         "--landmark-density", "0.3", "--out", (tmp_.path() / "seq").string()},
        tmp_.path() / "synth_logs");
    EXPECT_EQ(synth.exit_code, 0) << synth.err;
    const auto run = testing::RunProcess({CSLAM_BINARY, "run", (tmp_.path() / "seq").string(), "--out",
                                          out().string(), "--mode", "batch", "--no-progress"},
                                         tmp_.path() / "run_logs");
    EXPECT_EQ(run.exit_code, 0) << run.err;
  }
  fs::path out() const { return tmp_.path() / "out"; }
  fs::path png() const { return out() / "render" / "trajectory.png"; }
  testing::ProcessResult Render(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {CSLAM_BINARY, "render", out().string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunProcess(args, tmp_.path() / "render_logs");
  }
  /// Ids of the clusters in objects/index.csv with at least two poses (drawn as lines).
  /// Clusters the plot draws as lines (system/run/run_trajectory_plot.h decides which: the small
  /// ones are only counted in the legend).
  std::vector<int> ClustersWithLines() const {
    std::vector<int> ids;
    for (const RenderTrajectory& t : RunTrajectoryPlotLines(ReadRunOutputs(out().string())))
      if (t.cluster >= 1 && !t.positions.empty()) ids.push_back(t.cluster);
    return ids;
  }
  /// Rejected: the exit code, the message, no crash, and the picture as it was.
  void ExpectRejected(const testing::ProcessResult& r, const std::string& message,
                      const std::string& png_before) {
    EXPECT_FALSE(r.signalled) << r.err;
    EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_THAT(r.err, Not(HasSubstr("internal error")));
    EXPECT_EQ(fs::exists(png()) ? testing::ReadText(png()) : "", png_before);
    EXPECT_TRUE(testing::TemporaryFilesUnder(out()).empty());
  }
  testing::TempDir tmp_;
};

TEST_F(CliRender, RerenderOfAnUntouchedRunIsPixelEqualToTheRunsOwn) {
  const cv::Mat original = cv::imread(png().string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(original.empty()) << "the run wrote no " << png();
  fs::remove_all(out() / "render");
  const auto r = Render();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat again = cv::imread(png().string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(again.empty()) << r.err;
  ASSERT_EQ(again.size(), original.size());
  // Exactly equal, not just close: the trajectories are written in shortest exact decimals and
  // clusters.csv to 9 significant digits, which moves a centroid by far less than 1e-3 px.
  cv::Mat diff;
  cv::absdiff(original, again, diff);
  double max_diff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_EQ(max_diff, 0.0) << "the re-render differs from the run's own picture";

  // Not blank: the camera's black line and every drawn cluster in its colour.
  EXPECT_GT(testing::CountColour(again, {0, 0, 0}, 40), 200);
  const auto clusters = ClustersWithLines();
  ASSERT_FALSE(clusters.empty()) << "the run found no moving cluster: nothing coloured to check";
  for (int id : clusters) {
    if (r.err.find("cluster " + std::to_string(id) + " left out") != std::string::npos) continue;
    EXPECT_GT(testing::CountColour(again, BgrForCluster(id), 30), 20) << "cluster " << id;
  }
}

TEST_F(CliRender, ObjectsPictureDrawsEachObjectsTrackInItsColourAndRenderDrawsItTheSame) {
  const fs::path objects = out() / "render" / "objects.png";
  const cv::Mat original = cv::imread(objects.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(original.empty()) << "the run wrote no " << objects;
  EXPECT_EQ(original.size(), cv::Size(1200, 900));
  fs::remove_all(out() / "render");
  const auto r = Render();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat again = cv::imread(objects.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(again.size(), original.size()) << r.err;
  cv::Mat diff;
  cv::absdiff(original, again, diff);
  double max_diff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_EQ(max_diff, 0.0) << "the re-render differs from the run's own picture";

  // Every object's track shows in its colour over most of its length (other tracks and the
  // dashed truth may cross it), and the legend gives the matched ones' motion errors.
  std::ifstream metrics_file(out() / "metrics.json");
  const RunMetrics metrics = RunMetricsFromJson(nlohmann::json::parse(metrics_file));
  const auto lines = ObjectTrackPlotLines(ReadRunOutputs(out().string()), &metrics);
  const TopViewLayout layout = ComputeTopViewLayout(lines, 1200, 900);
  int tracks = 0, with_errors = 0;
  for (const RenderTrajectory& t : lines) {
    if (t.cluster < 1 || t.dashed) continue;
    ++tracks;
    with_errors += t.label.find(": ME_r ") != std::string::npos;
    double shown = 0, length = 0;
    for (size_t k = 1; k < t.positions.size(); ++k) {
      if (!t.positions[k - 1].allFinite() || !t.positions[k].allFinite()) continue;
      const Eigen::Vector2d a = layout.ToPixel(t.positions[k - 1]),
                            b = layout.ToPixel(t.positions[k]);
      shown += (b - a).norm() * testing::SegmentCoverage(again, a, b, BgrForCluster(t.cluster), 40);
      length += (b - a).norm();
    }
    if (length > 5) EXPECT_GT(shown / length, 0.6) << t.label;
  }
  EXPECT_GT(tracks, 0) << "the run reported no object: nothing coloured to check";
  EXPECT_GT(with_errors, 0) << "no object's legend row carries its ME_r / ME_t";
}

TEST_F(CliRender, GroundTruthOfTheEstimatedFramesIsAmongTheOutputs) {
  const auto estimate = testing::Lines(testing::ReadText(out() / "camera_trajectory.txt"));
  const auto truth = testing::Lines(testing::ReadText(out() / "camera_trajectory_gt.txt"));
  EXPECT_EQ(truth.size(), estimate.size());
  EXPECT_GE(truth.size(), static_cast<size_t>(kFrames));
  EXPECT_TRUE(fs::is_regular_file(out() / "camera_trajectory_gt.tum"));
}

TEST_F(CliRender, SizeFlagsSetThePictureSize) {
  const auto r = Render({"--width", "640", "--height", "480"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(cv::imread(png().string(), cv::IMREAD_COLOR).size(), cv::Size(640, 480));
  EXPECT_EQ(cv::imread((out() / "render" / "objects.png").string(), cv::IMREAD_COLOR).size(),
            cv::Size(640, 480));
}

TEST_F(CliRender, MissingCameraTrajectoryIsNamedAndNothingIsWritten) {
  fs::remove_all(out() / "render");
  fs::remove(out() / "camera_trajectory.txt");
  ExpectRejected(Render(), (out() / "camera_trajectory.txt").string() + ": missing", "");
  EXPECT_FALSE(fs::exists(out() / "render"));
}

TEST_F(CliRender, CorruptClustersLineIsNamedAndThePictureIsKept) {
  const std::string before = testing::ReadText(png());
  ASSERT_FALSE(before.empty());
  auto lines = testing::Lines(testing::ReadText(out() / "clusters.csv"));
  ASSERT_GT(lines.size(), 3u);
  lines[2] = "12,0,0,3,1.5,not-a-number,7";
  testing::WriteText(out() / "clusters.csv", testing::JoinLines(lines));
  ExpectRejected(Render(), (out() / "clusters.csv").string() + ":3: 'y': expected a finite number", before);
}

TEST_F(CliRender, NotARunFolderIsRejected) {
  const auto r = testing::RunProcess({CSLAM_BINARY, "render", (tmp_.path() / "seq").string()},
                                     tmp_.path() / "render_logs");
  EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("camera_trajectory.txt: missing"));
  EXPECT_FALSE(fs::exists(tmp_.path() / "seq" / "render"));
}

}  // namespace
}  // namespace cslam
