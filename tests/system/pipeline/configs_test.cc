// The YAML files in configs/ stay loadable as the options evolve (an unknown or renamed key
// is an error, core/options_reader.h), and each selects the preset its name promises.
#include <gtest/gtest.h>

#include <filesystem>

#include "system/pipeline/pipeline_options.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

TEST(Configs, EveryShippedConfigLoadsAndNamesItsPreset) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CSLAM_CONFIGS_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    ++n;
    const std::string name = entry.path().stem().string();
    SCOPED_TRACE(name);
    PipelineOptions o;
    ASSERT_NO_THROW(o = LoadPipelineOptions(Preset::kOutdoor, entry.path().string()));
    EXPECT_EQ(o.preset, name.find("indoor") != std::string::npos ? Preset::kIndoor : Preset::kOutdoor);
    EXPECT_EQ(o.mode, RunMode::kOnline);
  }
  EXPECT_GE(n, 4);
}

// `cslam run` without --config: a KITTI input gets its shipped config's estimation settings
// (the same tree as loading the file, renders aside); synthetic input keeps the built-in
// defaults.
TEST(Configs, KittiInputsWithoutAConfigGetTheirShippedSettings) {
  for (const InputKind input_kind : {InputKind::kKittiRaw, InputKind::kKittiOdometry}) {
    const std::string kind = NameOf(kInputKindNames, input_kind);
    SCOPED_TRACE(kind);
    const std::string file = std::string(CSLAM_CONFIGS_DIR) + "/" + kind + ".yaml";
    PipelineOptions builtin = LoadPipelineOptions(Preset::kOutdoor, "", input_kind);
    PipelineOptions loaded = LoadPipelineOptions(Preset::kOutdoor, file);
    EXPECT_NE(builtin.source.find("configs/" + kind + ".yaml"), std::string::npos);
    EXPECT_EQ(builtin.backend.motion.bundle_adjustment.far_depth_baselines, 35);
    EXPECT_TRUE(builtin.calibration.estimate_disparity_offset);
    EXPECT_EQ(builtin.output.snapshots_every, 0);
    EXPECT_GT(loaded.output.snapshots_every, 0);
    builtin.output = loaded.output;
    builtin.source = loaded.source;
    EXPECT_EQ(builtin.ToYaml(), loaded.ToYaml());
    // The shipped file given for its own kind of input is the recommended settings plus its
    // renders.
    PipelineOptions both = LoadPipelineOptions(Preset::kOutdoor, file, input_kind);
    both.source = loaded.source;
    EXPECT_EQ(both.ToYaml(), loaded.ToYaml());
  }
  const PipelineOptions synthetic = LoadPipelineOptions(Preset::kOutdoor, "", InputKind::kSynthetic);
  EXPECT_EQ(synthetic.source, "built-in defaults");
  EXPECT_FALSE(synthetic.calibration.estimate_disparity_offset);
}

// A user's file that tunes one value changes that value only: the recommended settings of
// the input kind stay under it (a file used to replace them, and a one-line tweak lost them).
TEST(Configs, AGivenFileChangesOnlyTheKeysItSetsOverTheRecommendedSettings) {
  const testing::TempDir tmp("configs_test");
  const std::filesystem::path file = tmp.path() / "one_key.yaml";
  testing::WriteText(file, "frontend:\n  stereo:\n    min_ncc: 0.8\n");
  const PipelineOptions recommended = LoadPipelineOptions(Preset::kOutdoor, "", InputKind::kKittiRaw);
  PipelineOptions tuned = LoadPipelineOptions(Preset::kOutdoor, file.string(), InputKind::kKittiRaw);
  EXPECT_DOUBLE_EQ(tuned.frontend.stereo.min_ncc, 0.8);
  EXPECT_NE(recommended.frontend.stereo.min_ncc, 0.8);
  EXPECT_EQ(tuned.backend.motion.bundle_adjustment.far_depth_baselines, 35);
  EXPECT_TRUE(tuned.calibration.estimate_disparity_offset);
  EXPECT_NE(tuned.source.find(file.string()), std::string::npos);
  EXPECT_NE(tuned.source.find("configs/kitti_raw.yaml"), std::string::npos);
  tuned.frontend.stereo.min_ncc = recommended.frontend.stereo.min_ncc;
  tuned.source = recommended.source;
  EXPECT_EQ(tuned.ToYaml(), recommended.ToYaml());
  // Without an input kind (or for synthetic input) the file lies over the plain defaults.
  const PipelineOptions plain = LoadPipelineOptions(Preset::kOutdoor, file.string());
  EXPECT_EQ(plain.backend.motion.bundle_adjustment.far_depth_baselines, 0);
}

}  // namespace
}  // namespace cslam
