#include "system/synthetic/synthetic_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

class SyntheticIo : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SyntheticOptions o;
    o.preset = "outdoor";
    o.seed = 11;
    o.frames = 30;
    o.landmark_density = 0.3;
    sequence_ = new SyntheticSequence(GenerateSynthetic(o));
  }
  static void TearDownTestSuite() { delete sequence_; }

  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("cslam_synth_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
             "_" + std::to_string(::getpid())))
               .string();
    fs::remove_all(dir_);
    WriteSynthetic(*sequence_, dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> Lines(const std::string& name) const {
    std::ifstream in(fs::path(dir_) / name);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    return lines;
  }
  void Rewrite(const std::string& name, const std::vector<std::string>& lines) const {
    std::ofstream out(fs::path(dir_) / name, std::ios::trunc);
    for (const auto& l : lines) out << l << '\n';
  }
  /// Replaces 1-based line `n` of a file.
  void ReplaceLine(const std::string& name, int n, const std::string& text) const {
    auto lines = Lines(name);
    lines.at(n - 1) = text;
    Rewrite(name, lines);
  }
  /// ReadSynthetic must throw InputError whose message names `where` (e.g. "times.txt:3").
  void ExpectInputError(const std::string& where) const {
    try {
      ReadSynthetic(dir_);
      ADD_FAILURE() << "no InputError for " << where;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  }
  static std::vector<std::string> Split(const std::string& s) {
    std::vector<std::string> f;
    std::stringstream in(s);
    for (std::string x; std::getline(in, x, ',');) f.push_back(x);
    return f;
  }
  static std::string Join(const std::vector<std::string>& f) {
    std::string s;
    for (size_t i = 0; i < f.size(); ++i) s += (i ? "," : "") + f[i];
    return s;
  }

  static SyntheticSequence* sequence_;
  std::string dir_;
};

SyntheticSequence* SyntheticIo::sequence_ = nullptr;

TEST_F(SyntheticIo, WriteThenReadGivesBackEveryValue) {
  const SyntheticSequence& a = *sequence_;
  ASSERT_TRUE(LooksLikeSynthetic(dir_));
  const SyntheticSequence b = ReadSynthetic(dir_);
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.camera.fx, a.camera.fx);
  EXPECT_EQ(b.camera.fy, a.camera.fy);
  EXPECT_EQ(b.camera.cx, a.camera.cx);
  EXPECT_EQ(b.camera.cy, a.camera.cy);
  EXPECT_EQ(b.camera.baseline, a.camera.baseline);
  EXPECT_EQ(b.camera.width, a.camera.width);
  EXPECT_EQ(b.camera.height, a.camera.height);
  EXPECT_EQ(b.timestamps, a.timestamps);
  ASSERT_EQ(b.num_frames(), a.num_frames());
  ASSERT_EQ(b.num_objects(), a.num_objects());
  for (int f = 0; f < a.num_frames(); ++f) {
    EXPECT_TRUE(b.world_from_cam[f].matrix() == a.world_from_cam[f].matrix());
    for (int o = 0; o < a.num_objects(); ++o)
      EXPECT_TRUE(b.world_from_object[o][f].matrix() == a.world_from_object[o][f].matrix());
  }
  EXPECT_EQ(b.landmark_object, a.landmark_object);
  EXPECT_EQ(b.landmark_in_object, a.landmark_in_object);
  ASSERT_EQ(b.observations.num_landmarks(), a.observations.num_landmarks());
  ASSERT_EQ(b.observations.num_observations(), a.observations.num_observations());
  for (int l = 0; l < a.observations.num_landmarks(); ++l) {
    const auto oa = a.observations.ObservationsOf(l), ob = b.observations.ObservationsOf(l);
    ASSERT_EQ(oa.size(), ob.size());
    for (size_t i = 0; i < oa.size(); ++i) {
      EXPECT_EQ(oa[i].frame, ob[i].frame);
      EXPECT_TRUE(oa[i].x == ob[i].x);
      EXPECT_TRUE(oa[i].cov == ob[i].cov);
    }
  }
  EXPECT_TRUE(b.geometry == a.geometry);
}

TEST_F(SyntheticIo, LooksLikeSyntheticNeedsTheFiles) {
  EXPECT_TRUE(LooksLikeSynthetic(dir_));
  fs::remove(fs::path(dir_) / "observations.csv");
  EXPECT_FALSE(LooksLikeSynthetic(dir_));
  EXPECT_FALSE(LooksLikeSynthetic(dir_ + "/nowhere"));
  ExpectInputError("observations.csv");
}

TEST_F(SyntheticIo, NonFiniteObservationNamesFileAndLine) {
  auto f = Split(Lines("observations.csv").at(2));
  f[2] = "nan";
  ReplaceLine("observations.csv", 3, Join(f));
  ExpectInputError("observations.csv:3");
}

TEST_F(SyntheticIo, NegativeDisparityIsRejected) {
  auto f = Split(Lines("observations.csv").at(4));
  std::swap(f[2], f[4]);
  ReplaceLine("observations.csv", 5, Join(f));
  ExpectInputError("observations.csv:5");
}

TEST_F(SyntheticIo, UnknownLandmarkIdIsRejected) {
  auto f = Split(Lines("observations.csv").at(1));
  f[1] = "999999";
  ReplaceLine("observations.csv", 2, Join(f));
  ExpectInputError("observations.csv:2");
}

TEST_F(SyntheticIo, MissingFieldIsRejected) {
  auto f = Split(Lines("observations.csv").at(6));
  f.pop_back();
  ReplaceLine("observations.csv", 7, Join(f));
  ExpectInputError("observations.csv:7");
}

TEST_F(SyntheticIo, LandmarkBehindTheCameraIsRejected) {
  // Move the first observed static landmark behind camera 0 (world = camera 0 frame).
  const SyntheticSequence& s = *sequence_;
  const auto obs_lines = Lines("observations.csv");
  for (size_t i = 1; i < obs_lines.size(); ++i) {
    const auto f = Split(obs_lines[i]);
    const int landmark = std::stoi(f[1]);
    if (std::stoi(f[0]) != 0 || s.landmark_object[landmark] != 0) continue;
    ReplaceLine("gt_landmarks.csv", landmark + 2, std::to_string(landmark) + ",0,0,0,-5");
    ExpectInputError("observations.csv:" + std::to_string(i + 1));
    return;
  }
  FAIL() << "no static landmark observed in frame 0";
}

TEST_F(SyntheticIo, UnknownObjectIdIsRejected) {
  ReplaceLine("gt_landmarks.csv", 4, "2,99,1,2,3");
  ExpectInputError("gt_landmarks.csv:4");
}

TEST_F(SyntheticIo, MalformedTimestampIsRejected) {
  ReplaceLine("times.txt", 3, "abc");
  ExpectInputError("times.txt:3");
}

TEST_F(SyntheticIo, MissingPoseLineIsACountError) {
  auto lines = Lines("gt_camera.txt");
  lines.pop_back();
  Rewrite("gt_camera.txt", lines);
  ExpectInputError("gt_camera.txt");
  try {
    ReadSynthetic(dir_);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected 30 poses"), std::string::npos) << e.what();
  }
}

TEST_F(SyntheticIo, NonRotationPoseIsRejected) {
  ReplaceLine("gt_objects/1.txt", 2, "2 0 0 0 0 1 0 0 0 0 1 0");
  ExpectInputError("1.txt:2");
}

TEST_F(SyntheticIo, ObservationCountMustMatchTheHeader) {
  auto lines = Lines("observations.csv");
  lines.pop_back();
  Rewrite("observations.csv", lines);
  ExpectInputError("observations.csv");
}

TEST_F(SyntheticIo, BadCameraValueIsRejected) {
  auto lines = Lines("camera.txt");
  for (auto& l : lines)
    if (l.rfind("baseline", 0) == 0) l = "baseline -0.5";
  Rewrite("camera.txt", lines);
  ExpectInputError("camera.txt");
}

}  // namespace
}  // namespace cslam
