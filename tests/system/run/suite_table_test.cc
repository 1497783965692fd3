// The suite's table (system/run/suite_table.h): rows read back from run folders (ok, failed
// with the log's error, incomplete without the marker), external trajectories scored against
// the input's ground truth, means per system, and the three files.
#include "system/run/suite_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "system/eval/trajectory_io.h"
#include "system/run/external_trajectory.h"
#include "system/run/run_executor.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class SuiteTableTest : public ::testing::Test {
 protected:
  SuiteTableTest() : tmp_("suite_table") {
    SyntheticOptions o;
    o.seed = 5;
    o.frames = 12;
    WriteSynthetic(GenerateSynthetic(o), seq().string());
  }
  fs::path seq() const { return tmp_.path() / "seq"; }
  SuiteRun Run(const std::string& id, const std::string& system) const {
    SuiteRun r;
    r.id = id;
    r.entry = id;
    r.drive = "seq";
    r.system = system;
    return r;
  }
  void WriteMetrics(const std::string& id, double ate) const {
    RunMetrics m;
    m.camera.ate_m = ate;
    m.timing.peak_rss_mb = 100;
    WriteMetricsJson(m, (tmp_.path() / "runs" / id / "metrics.json").string());
  }
  SuiteExternal External(const fs::path& file) const {
    SuiteExternal x;
    x.id = "peer";
    x.drive = "seq";
    x.input = seq().string();
    x.trajectory = file.string();
    x.system = "peer";
    return x;
  }
  testing::TempDir tmp_;
};

TEST_F(SuiteTableTest, RowsComeFromTheRunFolders) {
  const std::string runs = (tmp_.path() / "runs").string();
  WriteMetrics("good", 0.25);
  WriteCompletionMarker(runs + "/good", 0);
  fs::create_directories(runs + "/bad");
  testing::WriteText(runs + "/bad/console.log", "starting\ncslam run: error: tracking.foo: unknown key\n");
  WriteCompletionMarker(runs + "/bad", 2);
  WriteMetrics("unfinished", 9.0);  // metrics but no marker: interrupted, not complete

  const SuiteRow good = CollectRunRow(Run("good", "ours"), runs);
  EXPECT_EQ(good.status, "ok");
  ASSERT_TRUE(good.metrics);
  EXPECT_DOUBLE_EQ(*good.metrics->camera.ate_m, 0.25);
  const SuiteRow bad = CollectRunRow(Run("bad", "ours"), runs);
  EXPECT_EQ(bad.status, "failed");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.error, HasSubstr("exit code 2: cslam run: error: tracking.foo: unknown key"));
  EXPECT_THAT(bad.log_tail, HasSubstr("starting"));
  EXPECT_EQ(CollectRunRow(Run("unfinished", "ours"), runs).status, "incomplete");

  SuiteTable t;
  t.rows = {good, bad, CollectRunRow(Run("unfinished", "ours"), runs)};
  const std::vector<SuiteMeans> means = t.Means();
  ASSERT_EQ(means.size(), 1u);
  EXPECT_EQ(means[0].rows, 3);
  EXPECT_EQ(means[0].ok, 1);
  EXPECT_EQ(means[0].failed, 1);
  EXPECT_DOUBLE_EQ(*means[0].values[0], 0.25);
  EXPECT_EQ(t.Failed(), 1);
  EXPECT_EQ(t.Incomplete(), 1);

  WriteSuiteTable(t, tmp_.path().string());
  for (const char* f : {"bench.json", "bench.md", "bench.png"}) EXPECT_TRUE(fs::exists(tmp_.path() / f)) << f;
  const std::string md = testing::ReadText(tmp_.path() / "bench.md");
  EXPECT_THAT(md, HasSubstr("| good | seq | ours | ok | 0.250 |"));
  EXPECT_THAT(md, HasSubstr("### bad"));
  const nlohmann::json j = nlohmann::json::parse(testing::ReadText(tmp_.path() / "bench.json"));
  EXPECT_EQ(j["rows"][1]["status"], "failed");
  EXPECT_EQ(j["rows"][1]["exit_code"], 2);
  EXPECT_DOUBLE_EQ(j["means"][0]["values"]["camera_ate_m"].get<double>(), 0.25);
}

TEST_F(SuiteTableTest, ExternalTrajectoriesAreScoredAgainstTheSameGroundTruth) {
  const Trajectory gt = InputGroundTruth(seq().string(), 0);
  ASSERT_EQ(gt.size(), 12u);
  // The ground truth itself, KITTI (line k = frame k) and TUM (by timestamp): zero error.
  Trajectory kitti = gt;
  kitti.timestamps.clear();
  WriteTrajectory(kitti, (tmp_.path() / "gt.txt").string(), TrajectoryFormat::kKitti);
  Trajectory tum = gt;
  tum.frames.clear();
  WriteTrajectory(tum, (tmp_.path() / "gt.tum").string(), TrajectoryFormat::kTum);
  for (const char* f : {"gt.txt", "gt.tum"}) {
    const SuiteRow row = ScoreExternalRow(External(tmp_.path() / f));
    ASSERT_EQ(row.status, "ok") << f << ": " << row.error;
    EXPECT_NEAR(*row.metrics->camera.ate_m, 0.0, 1e-9) << f;
    EXPECT_NEAR(*row.metrics->camera.rpe_frame_t_m, 0.0, 1e-9) << f;
  }
  // Shifted by 1 m: ATE after SE(3) alignment stays 0, so shift one pose only.
  Trajectory moved = kitti;
  moved.poses[6].translation().x() += 1.0;
  WriteTrajectory(moved, (tmp_.path() / "moved.txt").string(), TrajectoryFormat::kKitti);
  const SuiteRow row = ScoreExternalRow(External(tmp_.path() / "moved.txt"));
  ASSERT_EQ(row.status, "ok") << row.error;
  EXPECT_GT(*row.metrics->camera.ate_m, 0.1);

  // A KITTI file one line short without a frames list: failed, naming the file and the rule.
  Trajectory shorter = kitti;
  shorter.poses.pop_back();
  shorter.frames.pop_back();
  WriteTrajectory(shorter, (tmp_.path() / "short.txt").string(), TrajectoryFormat::kKitti);
  const SuiteRow bad = ScoreExternalRow(External(tmp_.path() / "short.txt"));
  EXPECT_EQ(bad.status, "failed");
  EXPECT_THAT(bad.error, HasSubstr("short.txt"));
  EXPECT_THAT(bad.error, HasSubstr("has 11 poses but the input has 12 frames"));
  // ... and accepted with a frames list saying which frames they are.
  {
    std::ofstream f(tmp_.path() / "frames.txt");
    for (int i = 0; i < 11; ++i) f << i << "\n";
  }
  SuiteExternal with_frames = External(tmp_.path() / "short.txt");
  with_frames.frames = (tmp_.path() / "frames.txt").string();
  EXPECT_EQ(ScoreExternalRow(with_frames).status, "ok");
  // A file in no known format: the line is named.
  testing::WriteText(tmp_.path() / "junk.txt", "1 2 3\n");
  const SuiteRow junk = ScoreExternalRow(External(tmp_.path() / "junk.txt"));
  EXPECT_EQ(junk.status, "failed");
  EXPECT_THAT(junk.error, HasSubstr("junk.txt:1"));
}

}  // namespace
}  // namespace cslam
