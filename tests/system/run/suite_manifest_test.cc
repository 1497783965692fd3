// The suite manifest (system/run/suite_manifest.h): grids expand into runs, paths resolve
// relative to the manifest, and every bad input is a ConfigError naming the file, the line
// and the entry.
#include "system/run/suite_manifest.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "core/errors.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class SuiteManifestTest : public ::testing::Test {
 protected:
  SuiteManifestTest() : tmp_("suite_manifest") {
    // A folder of a known kind (synthetic: observations.csv) beside the manifest.
    testing::WriteText(tmp_.path() / "data" / "seq" / "observations.csv", "x\n");
    testing::WriteText(tmp_.path() / "configs" / "fast.yaml", "mode: batch\n");
    testing::WriteText(tmp_.path() / "peers" / "orb.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  }
  fs::path Write(const std::string& text) {
    const fs::path p = tmp_.path() / "suites" / "m.yaml";
    testing::WriteText(p, text);
    return p;
  }
  std::string ErrorOf(const std::string& text) {
    try {
      ReadSuiteManifest(Write(text).string());
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(no error)";
  }
  testing::TempDir tmp_;
};

TEST_F(SuiteManifestTest, GridExpandsAndPathsResolveRelativeToTheManifest) {
  const SuiteManifest m = ReadSuiteManifest(Write(R"(
defaults: {max_frames: 7}
entries:
  - name: a
    input: ../data/seq
    grid:
      method: [clusterslam, full-ba]
      ablation: [none, no-u]
  - input: ../data/seq
    name: b
    config: ../configs/fast.yaml
    max_frames: 3
  - synthetic: {preset: indoor, seed: 4, frames: 30}
  - name: peer
    input: ../data/seq
    trajectory: ../peers/orb.txt
    system: ORB-SLAM2
)").string());
  ASSERT_EQ(m.runs.size(), 6u);
  EXPECT_EQ(m.runs[0].id, "a-clusterslam-none");
  EXPECT_EQ(m.runs[3].id, "a-full-ba-no-u");
  EXPECT_EQ(m.runs[3].system, "full-ba/no-u");
  EXPECT_EQ(m.runs[3].method, "full-ba");
  EXPECT_EQ(m.runs[0].max_frames, 7);
  EXPECT_EQ(m.runs[0].input, (tmp_.path() / "data" / "seq").lexically_normal().string());
  EXPECT_EQ(m.runs[0].drive, "seq");
  EXPECT_EQ(m.runs[4].config, (tmp_.path() / "configs" / "fast.yaml").lexically_normal().string());
  EXPECT_EQ(m.runs[4].max_frames, 3);
  EXPECT_EQ(m.runs[4].system, "clusterslam@fast");
  EXPECT_EQ(m.runs[5].id, "synthetic_indoor_seed4_f30");
  ASSERT_TRUE(m.runs[5].synthetic);
  EXPECT_EQ(m.runs[5].synthetic->seed, 4);
  const std::vector<std::string> args = m.runs[4].RunArguments("IN", "OUT");
  EXPECT_EQ(args, (std::vector<std::string>{"run", "IN", "--out", "OUT", "--no-progress", "--config",
                                            m.runs[4].config, "--max-frames", "3"}));
  ASSERT_EQ(m.externals.size(), 1u);
  EXPECT_EQ(m.externals[0].system, "ORB-SLAM2");
  EXPECT_EQ(m.externals[0].trajectory, (tmp_.path() / "peers" / "orb.txt").lexically_normal().string());
}

TEST_F(SuiteManifestTest, UnknownKeyIsNamedWithItsLineAndEntry) {
  const std::string e = ErrorOf("entries:\n  - name: a\n    input: ../data/seq\n    methd: pdcs\n");
  EXPECT_THAT(e, HasSubstr("m.yaml:4"));
  EXPECT_THAT(e, HasSubstr("entry 'a'"));
  EXPECT_THAT(e, HasSubstr("unknown key 'methd'"));
  EXPECT_THAT(ErrorOf("entries: []\nrunz: 1\n"), HasSubstr("unknown key 'runz' in the manifest"));
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n    grid: {methods: [a]}\n"),
              HasSubstr("unknown key 'methods' in 'grid'"));
}

TEST_F(SuiteManifestTest, MissingOrUnknownFoldersAreNamed) {
  std::string e = ErrorOf("entries:\n  - name: gone\n    input: ../data/nope\n");
  EXPECT_THAT(e, HasSubstr("m.yaml:3: entry 'gone': 'input': "));
  EXPECT_THAT(e, HasSubstr("data/nope does not exist"));
  e = ErrorOf("entries:\n  - name: odd\n    input: ../configs\n");
  EXPECT_THAT(e, HasSubstr("entry 'odd'"));
  EXPECT_THAT(e, HasSubstr("is of no known kind"));
  EXPECT_THAT(ErrorOf("entries:\n  - name: x\n"), HasSubstr("give exactly one of 'input'"));
}

TEST_F(SuiteManifestTest, OtherMistakesAreRejected) {
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n  - input: ../data/seq\n"),
              HasSubstr("run name 'seq' is already used by the entry at line 2"));
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n    trajectory: ../peers/orb.txt\n"),
              HasSubstr("needs 'system'"));
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n    max_frames: many\n"),
              HasSubstr("'max_frames' must be an integer"));
  EXPECT_THAT(ErrorOf("entries:\n  - synthetic: {preset: underwater}\n"),
              HasSubstr("'preset' must be indoor or outdoor"));
  EXPECT_THAT(ErrorOf("entries: [\n"), HasSubstr("not valid YAML"));
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n    grid: {method: []}\n"),
              HasSubstr("grid 'method' must be a non-empty list"));
}

TEST_F(SuiteManifestTest, AnEntryChoosesTheCamerasOfItsRun) {
  const SuiteManifest m = ReadSuiteManifest(Write(R"(
defaults: {cameras: grey}
entries:
  - {name: colour, input: ../data/seq, cameras: color}
  - {name: grey, input: ../data/seq}
)").string());
  ASSERT_EQ(m.runs.size(), 2u);
  const auto colour = m.runs[0].RunArguments("IN", "OUT");
  const std::vector<std::string> flag = {"--cameras", "color"};
  EXPECT_NE(std::search(colour.begin(), colour.end(), flag.begin(), flag.end()), colour.end());
  EXPECT_EQ(m.runs[0].system, "clusterslam,color");
  EXPECT_EQ(m.runs[1].cameras, "grey");
  EXPECT_THAT(ErrorOf("entries:\n  - input: ../data/seq\n    cameras: rgb\n"),
              HasSubstr("'cameras' must be grey or color, got 'rgb'"));
}

}  // namespace
}  // namespace cslam
