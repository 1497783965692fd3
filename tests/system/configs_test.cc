// The YAML files in configs/ stay loadable as the options evolve (an unknown or renamed key
// is an error, core/options_reader.h), and each selects the preset its name promises.
#include <gtest/gtest.h>

#include <filesystem>

#include "system/pipeline_options.h"

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
    ASSERT_NO_THROW(o = LoadPipelineOptions("outdoor", entry.path().string()));
    EXPECT_EQ(o.preset, name.find("indoor") != std::string::npos ? "indoor" : "outdoor");
    EXPECT_EQ(o.mode, "online");
  }
  EXPECT_GE(n, 4);
}

}  // namespace
}  // namespace cslam
