// `cslam bench --suite FILE.yaml` run as a user would: a small manifest with a generated
// synthetic sequence, the real KITTI odometry clip, an entry that fails at start, and two
// external trajectories (one good, one a line short). Every run is its own `cslam run`
// process; the table has one row each; resume redoes only what has no completion marker;
// `collect` writes the same table again; bad manifests and all-failing suites exit non-zero.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>

#include "core/errors.h"
#include "tests/apps/subprocess.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kClipFrames = 20;

class CliBenchSuite : public ::testing::Test {
 protected:
  CliBenchSuite()
      : tmp_(std::string("cli_bench_suite_") +
             ::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    // The clip's ground truth, its first kClipFrames poses, as another system's "estimate".
    std::istringstream gt(testing::ReadText(testing::SharedData() / "kitti_odometry" / "poses" / "clip_a.txt"));
    std::string line, first, shorter;
    for (int i = 0; i < kClipFrames && std::getline(gt, line); ++i) {
      first += line + "\n";
      if (i + 1 < kClipFrames) shorter += line + "\n";
    }
    testing::WriteText(dir() / "peers" / "gt20.txt", first);
    testing::WriteText(dir() / "peers" / "gt19.txt", shorter);
    testing::WriteText(dir() / "bad.yaml", "no_such_section: {x: 1}\n");
  }
  fs::path dir() const { return tmp_.path() / "suite"; }
  fs::path out() const { return tmp_.path() / "out"; }
  std::string Clip() const { return fs::absolute(testing::OdometrySequenceDir()).string(); }
  fs::path Manifest(const std::string& name, const std::string& text) const {
    testing::WriteText(dir() / name, text);
    return dir() / name;
  }
  testing::ProcessResult Bench(const std::vector<std::string>& extra, const std::string& logs) {
    std::vector<std::string> args = {CSLAM_BINARY, "bench"};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::RunProcess(args, tmp_.path() / logs, {}, std::chrono::seconds(600));
  }
  nlohmann::json Json(const fs::path& p) const { return nlohmann::json::parse(testing::ReadText(p)); }
  const nlohmann::json& Row(const nlohmann::json& table, const std::string& id) const {
    for (const auto& r : table["rows"])
      if (r["id"] == id) return r;
    throw std::runtime_error("no row " + id);
  }
  testing::TempDir tmp_;
};

TEST_F(CliBenchSuite, RunsEveryEntryAsItsOwnProcessAndResumes) {
  const std::string frames = std::to_string(kClipFrames);
  const fs::path m = Manifest("m.yaml",
                              "entries:\n"
                              "  - synthetic: {preset: outdoor, seed: 3, frames: 30}\n"
                              "    mode: batch\n"
                              "  - name: clip_a\n    input: " + Clip() + "\n    max_frames: " + frames + "\n"
                              "  - name: broken\n    input: " + Clip() + "\n    config: bad.yaml\n"
                              "  - name: peer\n    input: " + Clip() + "\n    max_frames: " + frames + "\n"
                              "    trajectory: peers/gt20.txt\n    system: gt-copy\n"
                              "  - name: peer_short\n    input: " + Clip() + "\n    max_frames: " + frames + "\n"
                              "    trajectory: peers/gt19.txt\n    system: gt-copy\n");
  const auto r = Bench({"--suite", m.string(), "--out", out().string(), "--jobs", "2", "--no-progress"}, "first");
  ASSERT_FALSE(r.signalled) << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("runs 3/3 done, 0 running, 1 failed"));
  for (const char* f : {"bench.json", "bench.md", "bench.png", "suite.json"})
    EXPECT_TRUE(fs::exists(out() / f)) << f;
  EXPECT_TRUE(testing::TemporaryFilesUnder(out()).empty());

  const nlohmann::json table = Json(out() / "bench.json");
  ASSERT_EQ(table["rows"].size(), 5u);
  // Each run's figures are those of its own metrics.json, with the peak RSS in it.
  const std::string synth = "synthetic_outdoor_seed3_f30";
  for (const std::string id : {synth, std::string("clip_a")}) {
    const nlohmann::json& row = Row(table, id);
    EXPECT_EQ(row["status"], "ok") << row.dump(2);
    EXPECT_EQ(row["exit_code"], 0);
    const nlohmann::json metrics = Json(out() / "runs" / id / "metrics.json");
    EXPECT_EQ(row["values"]["camera_ate_m"], metrics["camera"]["ate_m"]) << id;
    EXPECT_GT(metrics["timing"]["peak_rss_mb"].get<double>(), 10.0) << id;
    EXPECT_EQ(testing::ReadText(out() / "runs" / id / "exit_code"), "0\n");
  }
  EXPECT_EQ(Row(table, "clip_a")["metrics"]["frames"], kClipFrames);
  // The failed run: its exit code (2: configuration) and the child's own message.
  const nlohmann::json& broken = Row(table, "broken");
  EXPECT_EQ(broken["status"], "failed");
  EXPECT_EQ(broken["exit_code"], kExitConfigError);
  EXPECT_THAT(broken["error"].get<std::string>(), HasSubstr("no_such_section"));
  EXPECT_THAT(broken["log_tail"].get<std::string>(), HasSubstr("no_such_section"));
  // The external trajectories: the ground truth itself scores zero; one line short is named.
  EXPECT_EQ(Row(table, "peer")["status"], "ok");
  EXPECT_LT(Row(table, "peer")["values"]["camera_ate_m"].get<double>(), 1e-6);
  EXPECT_EQ(Row(table, "peer_short")["status"], "failed");
  EXPECT_THAT(Row(table, "peer_short")["error"].get<std::string>(),
              HasSubstr("gt19.txt: has 19 poses but the input has 20 frames"));
  const std::string md = testing::ReadText(out() / "bench.md");
  EXPECT_THAT(md, HasSubstr("## Means per system"));
  EXPECT_THAT(md, HasSubstr("| clip_a | clip_a | clusterslam | ok |"));

  // The same figures as a separate `cslam run` of the same input (batch mode is deterministic).
  const auto sep = testing::RunProcess({CSLAM_BINARY, "run", (out() / "inputs" / synth).string(), "--mode",
                                        "batch", "--out", (tmp_.path() / "separate").string(), "--no-progress"},
                                       tmp_.path() / "separate_logs");
  ASSERT_EQ(sep.exit_code, 0) << sep.err;
  const nlohmann::json alone = Json(tmp_.path() / "separate" / "metrics.json");
  EXPECT_EQ(Row(table, synth)["metrics"]["camera"], alone["camera"]);
  EXPECT_EQ(Row(table, synth)["metrics"]["clustering"], alone["clustering"]);

  // Resume: the clip's marker removed, as if it had been interrupted; only it is run again.
  const auto synth_time = fs::last_write_time(out() / "runs" / synth / "metrics.json");
  fs::remove(out() / "runs" / "clip_a" / "exit_code");
  const auto again = Bench({"--suite", m.string(), "--out", out().string(), "--no-progress"}, "again");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err, HasSubstr("(2 already complete)"));
  EXPECT_THAT(again.err, HasSubstr("runs 3/3 done"));
  EXPECT_EQ(fs::last_write_time(out() / "runs" / synth / "metrics.json"), synth_time);
  EXPECT_TRUE(fs::exists(out() / "runs" / "clip_a" / "exit_code"));
  EXPECT_EQ(Row(Json(out() / "bench.json"), "clip_a")["status"], "ok");

  // `collect` writes the same rows again from the folders.
  fs::remove(out() / "bench.json");
  const auto collected = Bench({"collect", out().string()}, "collect");
  ASSERT_EQ(collected.exit_code, 0) << collected.err;
  const nlohmann::json recollected = Json(out() / "bench.json");
  ASSERT_EQ(recollected["rows"].size(), 5u);
  EXPECT_EQ(Row(recollected, "clip_a")["status"], "ok");
  EXPECT_EQ(Row(recollected, "broken")["exit_code"], kExitConfigError);
}

TEST_F(CliBenchSuite, ASuiteWhoseEveryRunFailsExitsNonZero) {
  const fs::path m = Manifest("fail.yaml", "entries:\n  - name: broken\n    input: " + Clip() +
                                               "\n    config: bad.yaml\n");
  const auto r = Bench({"--suite", m.string(), "--out", out().string(), "--no-progress"}, "fail");
  EXPECT_FALSE(r.signalled);
  EXPECT_EQ(r.exit_code, kExitNoEstimate) << r.err;
  EXPECT_THAT(r.err, HasSubstr("every run of the suite failed"));
  EXPECT_THAT(r.out, HasSubstr("failed: broken: exit code 2"));
  EXPECT_EQ(Json(out() / "bench.json")["rows"][0]["status"], "failed");
}

TEST_F(CliBenchSuite, BadManifestsAreNamedBeforeAnythingRuns) {
  const fs::path typo = Manifest("typo.yaml", "entries:\n  - name: a\n    input: " + Clip() + "\n    metod: pdcs\n");
  auto r = Bench({"--suite", typo.string(), "--out", out().string()}, "typo");
  EXPECT_EQ(r.exit_code, kExitConfigError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("typo.yaml:4: entry 'a': unknown key 'metod'"));
  EXPECT_FALSE(fs::exists(out()));

  const fs::path gone = Manifest("gone.yaml", "entries:\n  - name: far\n    input: ../nowhere/drive\n");
  r = Bench({"--suite", gone.string(), "--out", out().string()}, "gone");
  EXPECT_EQ(r.exit_code, kExitConfigError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("gone.yaml:3: entry 'far': 'input': "));
  EXPECT_THAT(r.err, HasSubstr("nowhere/drive does not exist"));
  EXPECT_FALSE(fs::exists(out()));

  r = Bench({"--suite", (dir() / "absent.yaml").string(), "--out", out().string()}, "missing");
  EXPECT_EQ(r.exit_code, kExitConfigError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("the suite manifest does not exist"));

  r = Bench({"collect", (tmp_.path() / "not_a_suite").string()}, "collect");
  EXPECT_EQ(r.exit_code, kExitInputError) << r.err;
  EXPECT_THAT(r.err, HasSubstr("suite.json: not found"));
}

// The Slurm executor's scripts run by a stand-in sbatch (this machine has no Slurm): it runs
// the array's tasks one after the other except task 1, which it "kills for time" (no marker);
// the stand-in sacct then reports TIMEOUT for it. The task that ran gives the local
// executor's figures; the killed one is a failed row naming the reason. Without sbatch on
// PATH the message says what to install.
TEST_F(CliBenchSuite, SlurmArrayScriptsRunAndKilledTasksAreMarked) {
  const fs::path m = Manifest("slurm.yaml",
                              "slurm: {time: \"00:10:00\", mem: 2G, cpus_per_task: 2}\n"
                              "entries:\n"
                              "  - synthetic: {preset: outdoor, seed: 3, frames: 30}\n    mode: batch\n"
                              "  - synthetic: {preset: outdoor, seed: 4, frames: 30}\n    mode: batch\n");
  const fs::path bin = tmp_.path() / "fake_slurm_bin";
  testing::WriteText(bin / "sbatch",
                     "#!/bin/sh\n# stand-in: sbatch --parsable SCRIPT\nscript=$2\n"
                     "cp \"$script\" \"$(dirname \"$script\")/submitted.sh\"\n"
                     "n=$(sed -n 's/^#SBATCH --array=0-//p' \"$script\")\n"
                     "k=0; while [ $k -le $n ]; do\n"
                     "  [ $k -ne 1 ] && SLURM_ARRAY_TASK_ID=$k sh \"$script\" > /dev/null 2>&1\n"
                     "  k=$((k+1)); done\necho 4242\n");
  testing::WriteText(bin / "squeue", "#!/bin/sh\nexit 0\n");
  testing::WriteText(bin / "sacct", "#!/bin/sh\necho '4242_0|COMPLETED|0:0'\necho '4242_1|TIMEOUT|0:0'\n");
  for (const char* f : {"sbatch", "squeue", "sacct"})
    fs::permissions(bin / f, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
  const std::string old_path = std::getenv("PATH") ? std::getenv("PATH") : "/usr/bin:/bin";
  setenv("PATH", (bin.string() + ":" + old_path).c_str(), 1);
  const auto r = Bench({"--suite", m.string(), "--out", out().string(), "--executor", "slurm",
                        "--slurm-poll", "0.1", "--no-progress"}, "slurm");
  fs::create_directories(tmp_.path() / "empty_bin");
  setenv("PATH", (tmp_.path() / "empty_bin").c_str(), 1);  // no sbatch
  const auto none = Bench({"--suite", m.string(), "--out", (tmp_.path() / "none").string(),
                           "--executor", "slurm"}, "no_sbatch");
  const fs::path refusing = tmp_.path() / "refusing_bin";
  testing::WriteText(refusing / "sbatch", "#!/bin/sh\necho 'sbatch: error: invalid partition specified: gpu' >&2\nexit 1\n");
  fs::permissions(refusing / "sbatch", fs::perms::owner_all);
  setenv("PATH", (refusing.string() + ":" + old_path).c_str(), 1);
  const auto refused = Bench({"--suite", m.string(), "--out", (tmp_.path() / "refused").string(),
                              "--executor", "slurm", "--slurm-partition", "gpu"}, "refused");
  setenv("PATH", old_path.c_str(), 1);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::string submitted = testing::ReadText(out() / "slurm" / "submitted.sh");
  EXPECT_THAT(submitted, HasSubstr("#SBATCH --array=0-1"));
  EXPECT_THAT(submitted, HasSubstr("#SBATCH --time=00:10:00"));
  EXPECT_THAT(submitted, HasSubstr("#SBATCH --mem=2G"));
  EXPECT_THAT(submitted, HasSubstr("#SBATCH --cpus-per-task=2"));
  const nlohmann::json table = Json(out() / "bench.json");
  EXPECT_EQ(table["executor"], "slurm");
  EXPECT_EQ(Row(table, "synthetic_outdoor_seed3_f30")["status"], "ok");
  const nlohmann::json& killed = Row(table, "synthetic_outdoor_seed4_f30");
  EXPECT_EQ(killed["status"], "failed");
  EXPECT_THAT(killed["error"].get<std::string>(), HasSubstr("Slurm task 4242_1 ended TIMEOUT"));

  // The same entry through the local executor: the same figures.
  const auto local = Bench({"--suite", m.string(), "--out", (tmp_.path() / "local").string(),
                            "--jobs", "2", "--no-progress"}, "local");
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const nlohmann::json local_table = Json(tmp_.path() / "local" / "bench.json");
  EXPECT_EQ(Row(table, "synthetic_outdoor_seed3_f30")["metrics"]["camera"],
            Row(local_table, "synthetic_outdoor_seed3_f30")["metrics"]["camera"]);
  EXPECT_EQ(Row(table, "synthetic_outdoor_seed3_f30")["metrics"]["clustering"],
            Row(local_table, "synthetic_outdoor_seed3_f30")["metrics"]["clustering"]);

  EXPECT_EQ(none.exit_code, kExitConfigError) << none.err;
  EXPECT_THAT(none.err, HasSubstr("sbatch not found on PATH"));
  EXPECT_THAT(none.err, HasSubstr("--executor local"));
  EXPECT_EQ(refused.exit_code, kExitConfigError) << refused.err;
  EXPECT_THAT(refused.err, HasSubstr("sbatch refused the job (exit 1): sbatch: error: invalid partition specified: gpu"));
  EXPECT_THAT(testing::ReadText(tmp_.path() / "refused" / "slurm" / "array.sh"), HasSubstr("#SBATCH --partition=gpu"));
}

}  // namespace
}  // namespace cslam
