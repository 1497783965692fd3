// What `cslam run` leaves in its output folder and says on the console (docs/usage.md,
// docs/reliability.md): an earlier run's outputs are never mixed with a new run's, --overwrite
// removes only what a run wrote, a picture that cannot be written loses no result, and the
// colour pair of a KITTI raw drive is used when asked for or when it is the only one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

#include "core/errors.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr int kFrames = 5;

class CliOutputs : public ::testing::Test {
 protected:
  CliOutputs()
      : tmp_(std::string("cli_outputs_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()),
        drive_(testing::MakeRawCopy(tmp_.path() / "data", kFrames)) {}

  testing::ProcessResult Run(const std::vector<std::string>& extra = {}, const fs::path& input = {}) {
    std::vector<std::string> args = {CSLAM_BINARY, "run", (input.empty() ? drive_ : input).string(),
                                     "--out", out().string(), "--no-progress"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunProcess(args, tmp_.path() / ("logs" + std::to_string(runs_++)));
  }
  fs::path out() const { return tmp_.path() / "out"; }

  testing::TempDir tmp_;
  fs::path drive_;
  int runs_ = 0;
};

TEST_F(CliOutputs, ASecondRunIntoTheSameFolderIsRefusedAndTheFirstRunsFilesStay) {
  const auto first = Run();
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // The console: the input line, where the configuration came from, the summary; the info
  // log (one line per window, the effective configuration) is in run.log only.
  EXPECT_THAT(first.out, HasSubstr("input: " + drive_.string()));
  EXPECT_THAT(first.out, HasSubstr("configuration: built-in configs/kitti_raw.yaml"));
  EXPECT_THAT(first.out, HasSubstr("camera: ATE"));
  EXPECT_THAT(first.err, Not(HasSubstr("[info]")));
  EXPECT_THAT(first.out + first.err, Not(HasSubstr("effective configuration")));
  EXPECT_THAT(testing::ReadText(out() / "run.log"), HasSubstr("effective configuration"));
  const std::string metrics = testing::ReadText(out() / "metrics.json");

  const auto second = Run();
  EXPECT_EQ(second.exit_code, kExitConfigError) << second.err;
  EXPECT_THAT(second.err, HasSubstr(out().string() + " holds the outputs of an earlier run; give --overwrite"));
  EXPECT_EQ(testing::ReadText(out() / "metrics.json"), metrics);
}

TEST_F(CliOutputs, VerboseBringsBackThePerWindowLog) {
  const auto r = Run({"-v"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("integrated"));
}

TEST_F(CliOutputs, OverwriteRemovesWhatTheEarlierRunWroteAndKeepsAUsersFile) {
  testing::WriteText(out() / "notes.txt", "mine");
  const auto first = Run({"--snapshots-every", "1"});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  ASSERT_TRUE(fs::exists(out() / "render" / "snapshot_000002.png"));
  const auto second = Run({"--overwrite", "--snapshots-every", "0"});
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_FALSE(fs::exists(out() / "render" / "snapshot_000002.png")) << "the earlier run's snapshot is left";
  EXPECT_TRUE(fs::exists(out() / "metrics.json"));
  EXPECT_EQ(testing::ReadText(out() / "notes.txt"), "mine");
  const std::string manifest = testing::ReadText(out() / "cslam_outputs.json");
  EXPECT_THAT(manifest, HasSubstr("\"complete\": true"));
  EXPECT_THAT(manifest, HasSubstr("\"notes.txt\""));  // listed as preexisting, not as ours
  EXPECT_THAT(manifest, HasSubstr("\"path\": \"" + drive_.string() + "\""));
}

TEST_F(CliOutputs, OverwriteOnAFolderThatIsNotACslamOutputIsRefusedAndRemovesNothing) {
  testing::WriteText(out() / "thesis.tex", "x");
  const auto r = Run({"--overwrite"});
  EXPECT_EQ(r.exit_code, kExitConfigError) << r.err;
  EXPECT_THAT(r.err, HasSubstr(out().string() + " is not a cslam output folder (no cslam_outputs.json)"));
  EXPECT_EQ(testing::ReadText(out() / "thesis.tex"), "x");
  EXPECT_FALSE(fs::exists(out() / "run.log"));
}

TEST_F(CliOutputs, ARenderFolderThatCannotBeWrittenLosesNoResultAndExitsThree) {
  // A file where render/ should be: no permission bit stops root, this does.
  testing::WriteText(out() / "render", "not a folder");
  const auto r = Run();
  EXPECT_FALSE(r.signalled) << r.err;
  EXPECT_EQ(r.exit_code, kExitOutputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("picture not written: render/trajectory.png"));
  EXPECT_THAT(r.err, HasSubstr("picture not written: render/objects.png"));
  EXPECT_THAT(r.out, HasSubstr("camera: ATE"));  // the summary
  for (const char* f : {"metrics.json", "camera_trajectory.txt", "camera_trajectory.tum", "clusters.csv"})
    EXPECT_GT(fs::file_size(out() / f), 0u) << f;
  EXPECT_TRUE(testing::TemporaryFilesUnder(out()).empty());
}

TEST_F(CliOutputs, ADriveWithOnlyTheColourPairRunsOnItAndRunLogSaysSo) {
  fs::rename(drive_ / "image_00", drive_ / "image_02");
  fs::rename(drive_ / "image_01", drive_ / "image_03");
  const auto r = Run();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("colour pair"));
  EXPECT_THAT(testing::ReadText(out() / "run.log"), HasSubstr("running on the colour pair image_02/03"));
  EXPECT_THAT(testing::ReadText(out() / "config.yaml"), HasSubstr("color: true"));
  EXPECT_THAT(testing::ReadText(out() / "cslam_outputs.json"), HasSubstr("\"cameras\": \"color\""));
}

TEST_F(CliOutputs, InputColorFromAConfigFileIsHonoured) {
  // The grey-only copy: a config asking for colour must say the colour pair is missing.
  testing::WriteText(tmp_.path() / "colour.yaml", "input: {color: true}\n");
  const auto r = Run({"--config", (tmp_.path() / "colour.yaml").string()});
  EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr((drive_ / "image_02").string()));
  EXPECT_THAT(r.err, HasSubstr("the colour pair was asked for"));
  EXPECT_FALSE(fs::exists(out()));
}

TEST_F(CliOutputs, FinalPicturesAreDrawnByDefaultAndRenderDrawsThemAgainFromTheRecordedInput) {
  const auto r = Run({"--pictures", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Frames 0..4 spread in two: the middles of 0-1 and 2-4 (SpreadFrames).
  const std::vector<std::string> pictures = {"final_snapshot_000001.png", "final_snapshot_000003.png",
                                             "final_overlay_000001.png", "final_overlay_000003.png"};
  std::map<std::string, std::string> drawn;
  for (const std::string& p : pictures) {
    ASSERT_TRUE(fs::exists(out() / "render" / p)) << p;
    drawn[p] = testing::ReadText(out() / "render" / p);
  }
  fs::remove_all(out() / "render");
  const auto again = testing::RunProcess({CSLAM_BINARY, "render", out().string()}, tmp_.path() / "render_logs");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  for (const std::string& p : pictures)
    EXPECT_EQ(testing::ReadText(out() / "render" / p), drawn[p]) << p << " is not drawn the same again";
}

TEST_F(CliOutputs, RenderOfAFolderWithoutAManifestNamesIt) {
  ASSERT_EQ(Run().exit_code, 0);
  fs::remove(out() / "cslam_outputs.json");  // as a run of a version before the manifest
  const auto r = testing::RunProcess({CSLAM_BINARY, "render", out().string()}, tmp_.path() / "render_logs");
  EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr((out() / "cslam_outputs.json").string() + ": missing"));
  EXPECT_TRUE(fs::exists(out() / "render" / "trajectory.png"));  // what needs no input is drawn
}

}  // namespace
}  // namespace cslam
