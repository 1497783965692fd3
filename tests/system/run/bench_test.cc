#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "system/run/bench_report.h"
#include "system/run/bench_suite.h"

namespace cslam {
namespace {

BenchEntry EntryWithAte(const std::string& preset, const std::string& method, double ate) {
  BenchEntry e;
  e.sequence = preset + "_seedX";
  e.preset = preset;
  e.method = FindBenchMethod(method);
  e.ok = true;
  e.metrics.camera.ate_m = ate;
  return e;
}

TEST(Bench, MethodsAreThePapersRowsInOrder) {
  std::vector<std::string> labels;
  for (const BenchMethod& m : BenchMethods()) labels.push_back(m.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"Full BA", "P. DCS", "Ours w/o U", "Ours w/o I", "Ours",
                                              "True labels"}));
  EXPECT_FALSE(FindBenchMethod("true-labels").in_paper);
  EXPECT_EQ(FindBenchMethod("clusterslam-no-i").ablation, "no-i");
}

TEST(Bench, UnknownMethodOrSuiteIsAConfigErrorNamingIt) {
  try {
    FindBenchMethod("magic");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'magic'"), std::string::npos) << e.what();
  }
  BenchOptions o;
  o.suite = "kitti";
  EXPECT_THROW(o.Check(), ConfigError);
  o.suite = "synthetic";
  o.methods = {"full-ba", "nope"};
  EXPECT_THROW(o.Check(), ConfigError);
  o.methods = {"clusterslam", "full-ba"};
  EXPECT_NO_THROW(o.Check());
  // Selected in the paper's order, whatever the order given.
  const auto selected = o.SelectedMethods();
  ASSERT_EQ(selected.size(), 2u);
  EXPECT_EQ(selected[0].key, "full-ba");
  EXPECT_EQ(selected[1].key, "clusterslam");
  // Without --methods: the paper's five rows; the true-labels reference only when asked.
  o.methods.clear();
  const auto paper = o.SelectedMethods();
  ASSERT_EQ(paper.size(), 5u);
  EXPECT_EQ(paper.back().key, "clusterslam");
  o.methods = {"true-labels", "clusterslam"};
  EXPECT_NO_THROW(o.Check());
  const auto with_reference = o.SelectedMethods();
  ASSERT_EQ(with_reference.size(), 2u);
  EXPECT_EQ(with_reference[1].key, "true-labels");
}

TEST(Bench, SuiteHasIndoorThenOutdoorSeeds) {
  BenchOptions o;
  const auto seqs = SuiteSequences(o);
  ASSERT_EQ(seqs.size(), 10u);
  EXPECT_EQ(seqs[0].preset, "indoor");
  EXPECT_EQ(seqs[5].seed, 6);
  EXPECT_EQ(seqs[6].preset, "outdoor");
  EXPECT_EQ(seqs[6].seed, 1);
}

TEST(Bench, MeansLeaveOutFailedRunsButCountThem) {
  std::vector<BenchEntry> entries = {EntryWithAte("indoor", "full-ba", 1.0),
                                     EntryWithAte("indoor", "full-ba", 3.0),
                                     EntryWithAte("indoor", "full-ba", 100.0)};
  entries[2].ok = false;
  entries[2].error = "boom";
  std::vector<const BenchEntry*> group;
  for (const auto& e : entries) group.push_back(&e);
  const BenchMeans m = MeanOverEntries(group);
  EXPECT_EQ(m.runs, 3);
  EXPECT_EQ(m.failed, 1);
  size_t ate = 0;
  while (BenchColumns()[ate].key != "camera_ate_m") ++ate;
  ASSERT_TRUE(m.values[ate]);
  EXPECT_DOUBLE_EQ(*m.values[ate], 2.0);
  // A column no entry has stays unset (written as null / "—"), not zero.
  EXPECT_FALSE(m.values[0]);
}

TEST(Bench, AThrowingMethodIsRecordedAsFailedWithItsMessage) {
  const BenchSequence seq{"outdoor", 1, 1.5};
  const RunInput input = GenerateBenchInput(seq, 20);
  EXPECT_EQ(input.num_frames(), 20);
  const BenchMethod& ours = FindBenchMethod("clusterslam");
  PipelineOptions options = BenchPipelineOptions("outdoor", ours);
  options.backend.max_iterations = 0;  // the backend's own Check() throws on this
  const BenchEntry failed = RunBenchEntry(input, seq, ours, options);
  EXPECT_FALSE(failed.ok);
  EXPECT_NE(failed.error.find("max_iterations"), std::string::npos) << failed.error;

  BenchReport report;
  report.methods = {ours};
  report.entries = {failed};
  const nlohmann::json j = BenchToJson(report);
  ASSERT_EQ(j["entries"].size(), 1u);
  EXPECT_FALSE(j["entries"][0]["ok"].get<bool>());
  EXPECT_EQ(j["entries"][0]["error"].get<std::string>(), failed.error);
  EXPECT_EQ(j["means"][0]["failed"].get<int>(), 1);
  EXPECT_NE(BenchMarkdown(report).find("| outdoor_seed1 | Ours | failed: "), std::string::npos);
}

TEST(Bench, ARunOnAShortSequenceHasFiniteCameraErrors) {
  const BenchSequence seq{"indoor", 1, 1.5};
  const RunInput input = GenerateBenchInput(seq, 20);
  const BenchMethod& full_ba = FindBenchMethod("full-ba");
  const BenchEntry e = RunBenchEntry(input, seq, full_ba, BenchPipelineOptions("indoor", full_ba));
  ASSERT_TRUE(e.ok) << e.error;
  ASSERT_TRUE(e.metrics.camera.ate_m);
  EXPECT_TRUE(std::isfinite(*e.metrics.camera.ate_m));
  EXPECT_EQ(e.metrics.frames, 20);
  EXPECT_EQ(e.chunk_length, BenchPipelineOptions("indoor", full_ba).backend.consensus.chunk_length);
}

TEST(Bench, MarkdownWritesADivergedEstimateInScientificNotation) {
  BenchReport report;
  report.methods = {FindBenchMethod("full-ba")};
  report.entries = {EntryWithAte("outdoor", "full-ba", 1.5e50), EntryWithAte("outdoor", "full-ba", 0.0125)};
  const std::string md = BenchMarkdown(report);
  EXPECT_NE(md.find("| 1.50e+50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 0.013 |"), std::string::npos) << md;  // the second row, 3 decimals
}

TEST(Bench, ChunkLengthOverrideKeepsTheOverlapBelowIt) {
  const PipelineOptions o = BenchPipelineOptions("indoor", FindBenchMethod("clusterslam"), 30);
  EXPECT_EQ(o.backend.consensus.chunk_length, 30);
  EXPECT_LT(o.backend.consensus.chunk_overlap, 30);
  EXPECT_EQ(o.mode, RunMode::kBatch);
}

}  // namespace
}  // namespace cslam
