// The YAML files in configs/ stay loadable as the options evolve (an unknown or renamed key
// is an error, core/options_reader.h), and each selects the preset its name promises.
#include <gtest/gtest.h>

#include <filesystem>

#include "system/pipeline/pipeline_options.h"

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
// (the same tree as loading the file, renders aside); a given file wins; synthetic input keeps
// the built-in defaults.
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
  }
  const PipelineOptions given =
      LoadPipelineOptions(Preset::kOutdoor, std::string(CSLAM_CONFIGS_DIR) + "/synthetic_outdoor.yaml", InputKind::kKittiRaw);
  EXPECT_EQ(given.backend.motion.bundle_adjustment.far_depth_baselines, 0);
  const PipelineOptions synthetic = LoadPipelineOptions(Preset::kOutdoor, "", InputKind::kSynthetic);
  EXPECT_EQ(synthetic.source, "built-in defaults");
  EXPECT_FALSE(synthetic.calibration.estimate_disparity_offset);
}

}  // namespace
}  // namespace cslam
