// The whole configuration tree is loaded one way (OptionsReader::LoadInto / ReadSection): a
// misspelt key is an error in every section, and every message names the key path as the
// YAML file writes it.
#include "system/pipeline/pipeline_options.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/errors.h"

namespace cslam {
namespace {

std::string LoadError(const std::string& yaml) {
  try {
    auto r = OptionsReader::FromString(yaml, "config.yaml");
    PipelineOptions o;
    r.LoadInto(&o);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// "a.b.c" and "1" → "a:\n  b:\n    c: 1\n".
std::string NestedYaml(const std::string& path, const std::string& value) {
  std::string yaml, indent, rest = path;
  for (std::size_t dot; (dot = rest.find('.')) != std::string::npos; rest = rest.substr(dot + 1)) {
    yaml += indent + rest.substr(0, dot) + ":\n";
    indent += "  ";
  }
  return yaml + indent + rest + ": " + value + "\n";
}

int Depth(const std::string& path) { return static_cast<int>(std::count(path.begin(), path.end(), '.')); }

class MisspeltKey : public ::testing::TestWithParam<std::string> {};

// `path` ends in a key that does not exist; its section does.
TEST_P(MisspeltKey, IsAnErrorNamingFileLineAndPath) {
  const std::string path = GetParam();
  const std::string msg = LoadError(NestedYaml(path, "1"));
  const std::string line = std::to_string(Depth(path) + 1);
  EXPECT_EQ(msg.rfind("config.yaml:" + line + ": " + path + ": unknown key (known: ", 0), 0u) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    EveryTopLevelSection, MisspeltKey,
    ::testing::Values("presett", "input.bogus_key", "frontend.bogus_key", "backend.max_iteration",
                      "online.bogus_key", "batch.bogus_key", "map.bogus_key", "sanity.bogus_key",
                      "calibration.bogus_key", "output.bogus_key"));

INSTANTIATE_TEST_SUITE_P(
    NestedSections, MisspeltKey,
    ::testing::Values("backend.hac.epsilom", "backend.distance.bogus_key",
                      "backend.consensus.bogus_key", "backend.motion.bogus_key",
                      "backend.motion.shape_init.bogus_key",
                      "backend.motion.bundle_adjustment.max_iteration",
                      "backend.assignment.bogus_key", "backend.assignment.moving_test.bogus_key",
                      "backend.window_prior.bogus_key", "frontend.detector.bogus_key",
                      "frontend.tracker.max_fb_eror_px", "frontend.stereo.bogus_key",
                      "frontend.covariance.bogus_key", "calibration.disparity_offset.bogus_key"));

TEST(PipelineOptions, AnUnknownKeyListsTheKnownKeysOfItsSection) {
  EXPECT_EQ(LoadError("backend:\n  max_iteration: 3\n").rfind(
                "config.yaml:2: backend.max_iteration: unknown key (known: distance, hac, consensus, "
                "motion, assignment, window_prior, ablation, max_iterations,",
                0),
            0u);
  const std::string top = LoadError("frontend: {}\npresett: indoor\n");
  EXPECT_EQ(top.rfind("config.yaml:2: presett: unknown key (known: preset, method, ablation, mode, "
                      "backend_threads, frontend_threads, input, frontend, backend,",
                      0),
            0u)
      << top;
}

// A bad value, set in a YAML file at the key path Check() names, is rejected with a message
// naming that file, the line and the same path: the paths Check() uses are the YAML's.
struct BadValue {
  std::string path;
  std::string value;
  std::function<void(PipelineOptions&)> set;
};

class CheckNamesTheYamlPath : public ::testing::TestWithParam<BadValue> {};

TEST_P(CheckNamesTheYamlPath, InCheckAndWhenLoadingAFile) {
  const BadValue& bad = GetParam();
  PipelineOptions o;
  bad.set(o);
  try {
    o.Check();
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), bad.path) << e.what();
  }
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("cslam_options_test_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(file) << "mode: online\n" << NestedYaml(bad.path, bad.value);
  std::string msg;
  try {
    LoadPipelineOptions(Preset::kOutdoor, file.string());
  } catch (const ConfigError& e) {
    msg = e.what();
  }
  std::filesystem::remove(file);
  const std::string where =
      file.string() + ":" + std::to_string(Depth(bad.path) + 2) + ": " + bad.path + ": ";
  EXPECT_EQ(msg.rfind(where, 0), 0u) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    EverySection, CheckNamesTheYamlPath,
    ::testing::Values(
        BadValue{"backend_threads", "0", [](auto& o) { o.backend_threads = 0; }},
        BadValue{"frontend_threads", "0", [](auto& o) { o.frontend_threads = 0; }},
        BadValue{"input.max_frames", "-1", [](auto& o) { o.input.max_frames = -1; }},
        BadValue{"frontend.reinit_below_tracks", "-1",
                 [](auto& o) { o.frontend.reinit_below_tracks = -1; }},
        BadValue{"frontend.tracker.max_fb_error_px", "0",
                 [](auto& o) { o.frontend.tracker.max_fb_error_px = 0; }},
        BadValue{"backend.max_iterations", "0", [](auto& o) { o.backend.max_iterations = 0; }},
        BadValue{"backend.distance.alpha", "-1", [](auto& o) { o.backend.distance.alpha = -1; }},
        BadValue{"backend.hac.epsilon", ".nan", [](auto& o) { o.backend.hac.epsilon = NAN; }},
        BadValue{"backend.consensus.max_iterations", "0",
                 [](auto& o) { o.backend.consensus.max_iterations = 0; }},
        BadValue{"backend.motion.bundle_adjustment.num_threads", "0",
                 [](auto& o) { o.backend.motion.bundle_adjustment.num_threads = 0; }},
        BadValue{"backend.motion.shape_init.min_points", "2",
                 [](auto& o) { o.backend.motion.shape_init.min_points = 2; }},
        BadValue{"backend.assignment.min_coverage", "0",
                 [](auto& o) { o.backend.assignment.min_coverage = 0; }},
        BadValue{"backend.assignment.moving_test.false_alarm", "2",
                 [](auto& o) { o.backend.assignment.moving_test.false_alarm = 2; }},
        BadValue{"backend.window_prior.max_iterations", "0",
                 [](auto& o) { o.backend.window_prior.max_iterations = 0; }},
        BadValue{"online.window_frames", "2", [](auto& o) { o.online.window_frames = 2; }},
        BadValue{"batch.max_iterations", "0", [](auto& o) { o.batch.max_iterations = 0; }},
        BadValue{"map.min_shared_for_alignment", "2",
                 [](auto& o) { o.map.min_shared_for_alignment = 2; }},
        BadValue{"sanity.max_step_depths", "0", [](auto& o) { o.sanity.max_step_depths = 0; }},
        BadValue{"calibration.disparity_offset_frames", "2",
                 [](auto& o) { o.calibration.disparity_offset_frames = 2; }},
        BadValue{"calibration.disparity_offset.max_iterations", "0",
                 [](auto& o) { o.calibration.disparity_offset.max_iterations = 0; }},
        BadValue{"output.snapshots_every", "-1", [](auto& o) { o.output.snapshots_every = -1; }}));

TEST(PipelineOptions, TheAblationHasOneSpellingInYamlAndOnTheCommandLine) {
  auto r = OptionsReader::FromString("ablation: no-u\n", "config.yaml");
  PipelineOptions o;
  r.LoadInto(&o);
  EXPECT_EQ(o.ablation, ClusterSlamAblation::kNoUncertainty);
  EXPECT_EQ(o.backend.ablation, ClusterSlamAblation::kNoUncertainty);
  EXPECT_NE(o.ToYaml().find("ablation: no-u"), std::string::npos);
  EXPECT_EQ(LoadError("ablation: no_u\n"),
            "config.yaml:1: ablation: must be one of none, no-u, no-i, p2p-icp, got 'no_u'");
  EXPECT_EQ(LoadError("backend:\n  ablation: p2p_icp\n"),
            "config.yaml:2: backend.ablation: must be one of none, no-u, no-i, p2p-icp, got 'p2p_icp'");
}

TEST(PipelineOptions, PresetMethodAndModeAreReadByTheirTables) {
  auto r = OptionsReader::FromString("preset: indoor\nmethod: full-ba\nmode: batch\n", "config.yaml");
  PipelineOptions o;
  r.LoadInto(&o);
  EXPECT_EQ(o.preset, Preset::kIndoor);
  EXPECT_EQ(o.backend.hac.epsilon, ClusterSlamOptions::Indoor().hac.epsilon);
  EXPECT_EQ(o.method, Method::kFullBa);
  EXPECT_EQ(o.mode, RunMode::kBatch);
  EXPECT_EQ(LoadError("method: full_ba\n"),
            "config.yaml:1: method: must be one of clusterslam, full-ba, pdcs, true-labels, got 'full_ba'");
  EXPECT_EQ(LoadError("mode: offline\n"), "config.yaml:1: mode: must be one of online, batch, got 'offline'");
  EXPECT_EQ(LoadError("preset: forest\n"), "config.yaml:1: preset: must be one of indoor, outdoor, got 'forest'");
}

TEST(PipelineOptions, TheEffectiveConfigurationLoadsBackUnchanged) {
  PipelineOptions o;
  o.ApplyPreset(Preset::kIndoor);
  o.ApplyAblation(ClusterSlamAblation::kPointToPointIcp);
  o.method = Method::kPdcs;
  o.mode = RunMode::kBatch;
  auto r = OptionsReader::FromString(o.ToYaml(), "dump");
  PipelineOptions back;
  r.LoadInto(&back);
  EXPECT_EQ(back.ToYaml(), o.ToYaml());
  EXPECT_EQ(back.preset, Preset::kIndoor);
  EXPECT_EQ(back.ablation, ClusterSlamAblation::kPointToPointIcp);
  EXPECT_EQ(back.method, Method::kPdcs);
  EXPECT_EQ(back.mode, RunMode::kBatch);
}

}  // namespace
}  // namespace cslam
