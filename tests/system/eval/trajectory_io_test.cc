#include "system/eval/trajectory_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "core/errors.h"
#include "system/eval/trajectory_metrics.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

class TrajectoryIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cslam_trajectory_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  // Expects ReadTrajectory to throw InputError whose message starts with "path:line:".
  void ExpectInputError(const std::string& path, TrajectoryFormat format, int line,
                        const std::string& fragment) {
    try {
      ReadTrajectory(path, format);
      ADD_FAILURE() << "no error for " << path;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(fragment), std::string::npos) << what;
    }
  }

  fs::path dir_;
};

Trajectory RandomTrajectory(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 2.0);
  Trajectory t;
  for (int k = 0; k < n; ++k) {
    Vector6d xi;
    xi << g(rng) * 0.5, g(rng) * 0.5, g(rng) * 0.5, g(rng) * 50, g(rng), g(rng) * 100;
    t.poses.push_back(PoseFromVector(xi));
    t.frames.push_back(k);
    t.timestamps.push_back(1317384506.123456789 + 0.1036 * k);
  }
  return t;
}

TEST_F(TrajectoryIo, KittiRoundTripIsExact) {
  Trajectory t = RandomTrajectory(25, 1);
  t.timestamps.clear();
  const std::string path = (dir_ / "est.txt").string();
  WriteTrajectory(t, path, TrajectoryFormat::kKitti);
  EXPECT_FALSE(fs::exists(FrameIndexPathFor(path)));  // frames are 0..n-1
  EXPECT_EQ(GuessTrajectoryFormat(path), TrajectoryFormat::kKitti);
  const Trajectory r = ReadTrajectory(path, TrajectoryFormat::kKitti);
  ASSERT_EQ(r.size(), t.size());
  EXPECT_EQ(r.frames, t.frames);
  EXPECT_FALSE(r.HasTimestamps());
  for (size_t k = 0; k < t.size(); ++k)
    EXPECT_TRUE(testing::MatrixNear(r.poses[k].matrix(), t.poses[k].matrix(), 1e-14));
}

TEST_F(TrajectoryIo, TumRoundTripKeepsFullPrecision) {
  const Trajectory t = RandomTrajectory(25, 2);
  const std::string path = (dir_ / "est.tum").string();
  WriteTrajectory(t, path, TrajectoryFormat::kTum);
  EXPECT_EQ(GuessTrajectoryFormat(path), TrajectoryFormat::kTum);
  const Trajectory r = ReadTrajectory(path, TrajectoryFormat::kTum);
  ASSERT_EQ(r.size(), t.size());
  EXPECT_EQ(r.timestamps, t.timestamps);  // bit-exact: shortest round-trip text
  EXPECT_FALSE(r.HasFrames());
  for (size_t k = 0; k < t.size(); ++k)
    EXPECT_TRUE(testing::MatrixNear(r.poses[k].matrix(), t.poses[k].matrix(), 1e-14));
  // Single spaces, 8 fields.
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(std::count(line.begin(), line.end(), ' '), 7);
  EXPECT_EQ(line.find("  "), std::string::npos);
}

TEST_F(TrajectoryIo, KittiObjectTrajectoryKeepsItsFrames) {
  Trajectory t = RandomTrajectory(4, 3);
  t.timestamps.clear();
  t.frames = {3, 4, 9, 10};
  const std::string path = (dir_ / "objects" / "7.txt").string();
  WriteTrajectory(t, path, TrajectoryFormat::kKitti);
  ASSERT_TRUE(fs::exists(FrameIndexPathFor(path)));
  EXPECT_EQ(ReadTrajectory(path, TrajectoryFormat::kKitti).frames, t.frames);
  // Rewritten with frames 0..n-1, the stale index file must go.
  t.frames = {0, 1, 2, 3};
  WriteTrajectory(t, path, TrajectoryFormat::kKitti);
  EXPECT_FALSE(fs::exists(FrameIndexPathFor(path)));
  EXPECT_EQ(ReadTrajectory(path, TrajectoryFormat::kKitti).frames, t.frames);
}

TEST_F(TrajectoryIo, TumWithoutTimestampsWritesFrameIndices) {
  Trajectory t = RandomTrajectory(3, 4);
  t.timestamps.clear();
  t.frames = {5, 6, 8};
  const std::string path = (dir_ / "o.tum").string();
  WriteTrajectory(t, path, TrajectoryFormat::kTum);
  EXPECT_EQ(ReadTrajectory(path, TrajectoryFormat::kTum).timestamps,
            (std::vector<double>{5, 6, 8}));
}

TEST_F(TrajectoryIo, ReadsToleratedVariants) {
  // Comments, blank lines, tabs, a '+' sign and 6-digit rotations (KITTI's own files).
  const std::string path =
      Write("gt.txt",
            "# comment\n"
            "1.000000e+00 0 0 +1.5 0 1 0 0 0 0 1 0\n"
            "\n"
            "9.999995e-01\t7.196824e-04 -6.870876e-04 -1.401751e-02 -7.197717e-04 "
            "9.999997e-01 -1.295633e-04 -2.820321e-02 6.869946e-04 1.300585e-04 "
            "9.999998e-01 1.198998e+00\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kKitti);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.frames, (std::vector<int>{0, 1}));
  EXPECT_DOUBLE_EQ(t.poses[0].translation().x(), 1.5);
  EXPECT_NEAR(
      (t.poses[1].linear().transpose() * t.poses[1].linear() - Eigen::Matrix3d::Identity()).norm(),
      0, 1e-12);
}

TEST_F(TrajectoryIo, MalformedLinesNameFileAndLine) {
  const std::string ok = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  ExpectInputError(Write("a.txt", ok + ok + "1 0 0 0 0 1 0 0 0 0 1\n"), TrajectoryFormat::kKitti, 3,
                   "expected 12 numbers");
  ExpectInputError(Write("b.txt", ok + "1 0 0 nan 0 1 0 0 0 0 1 0\n"), TrajectoryFormat::kKitti, 2,
                   "finite");
  ExpectInputError(Write("c.txt", ok + "1 0 0 x 0 1 0 0 0 0 1 0\n"), TrajectoryFormat::kKitti, 2,
                   "'x'");
  ExpectInputError(Write("d.txt", "1 0 0 0 0 1.01 0 0 0 0 1 0\n"), TrajectoryFormat::kKitti, 1,
                   "orthonormal");
  ExpectInputError(Write("e.txt", "-1 0 0 0 0 1 0 0 0 0 1 0\n"), TrajectoryFormat::kKitti, 1,
                   "determinant");
  ExpectInputError(Write("f.tum", "0.0 1 2 3 0 0 0 1\n0.1 1 2 3 0 0 0\n"), TrajectoryFormat::kTum,
                   2, "expected 8 fields");
  ExpectInputError(Write("g.tum", "0.0 1 2 3 0 0 0 2\n"), TrajectoryFormat::kTum, 1,
                   "unit quaternion");
  ExpectInputError(Write("h.tum", "0.5 1 2 3 0 0 0 1\n0.4 1 2 3 0 0 0 1\n"), TrajectoryFormat::kTum,
                   2, "non-decreasing");
  ExpectInputError(Write("i.tum", "0.5 1 2 inf 0 0 0 1\n"), TrajectoryFormat::kTum, 1, "finite");
}

TEST_F(TrajectoryIo, GuessRejectsOtherFieldCountsAndMissingFiles) {
  const std::string bad = Write("bad.txt", "# header\n1 2 3 4 5\n");
  try {
    GuessTrajectoryFormat(bad);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad + ":2: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(GuessTrajectoryFormat(Write("empty.txt", "")), InputError);
  EXPECT_THROW(ReadTrajectory((dir_ / "missing.txt").string(), TrajectoryFormat::kKitti),
               InputError);
}

TEST_F(TrajectoryIo, FrameIndexFileMustMatchThePoses) {
  const std::string path = Write("o.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  Write("o_frames.txt", "4\n");
  EXPECT_THROW(ReadTrajectory(path, TrajectoryFormat::kKitti), InputError);
  Write("o_frames.txt", "4\n3\n");
  try {
    ReadTrajectory(path, TrajectoryFormat::kKitti);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir_ / "o_frames.txt").string() + ":2: ", 0), 0u) << e.what();
  }
}

TEST(TrajectoryIoRealData, ReadsKittiOdometryGroundTruth) {
  const std::string path = std::string(CSLAM_SHARED_DATA_DIR) + "/kitti_odometry/poses/clip_a.txt";
  if (!fs::exists(path)) GTEST_SKIP() << "no shared data at " << path;
  const Trajectory gt = ReadTrajectory(path, TrajectoryFormat::kKitti);
  ASSERT_EQ(gt.size(), 51u);
  EXPECT_TRUE(testing::PoseNear(gt.poses[0], Pose::Identity(), 1e-6, 1e-6));
  // README: ~60 m of straight driving.
  EXPECT_NEAR(PathLength(gt), 60.0, 2.0);
  EXPECT_LT(ComputeAte(gt, gt).rmse_m, 1e-9);
}

}  // namespace
}  // namespace cslam
