#include "system/run/run_outputs_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "core/errors.h"
#include "system/eval/trajectory_io.h"
#include "tests/system/kitti_fixtures.h"
#include "tests/support/poses.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using testing::Translation;

Trajectory Straight(const std::vector<int>& frames, double x) {
  Trajectory t;
  for (int f : frames) {
    t.frames.push_back(f);
    t.poses.push_back(Translation(x, 0.0, 1.0 * f));
  }
  return t;
}

/// A small output folder as the run writer lays it out: camera frames 0..5, ground truth,
/// cluster 3 seen in frames 2..4, two landmarks.
class RunOutputsReader : public ::testing::Test {
 protected:
  RunOutputsReader() : tmp_("run_outputs_reader"), out_(tmp_.path() / "out") {
    WriteTrajectory(Straight({0, 1, 2, 3, 4, 5}, 0.0), (out_ / "camera_trajectory.txt").string(),
                    TrajectoryFormat::kKitti);
    WriteTrajectory(Straight({0, 1, 2, 3, 4, 5}, 0.5), (out_ / "camera_trajectory_gt.txt").string(),
                    TrajectoryFormat::kKitti);
    WriteTrajectory(Straight({2, 3, 4}, 4.0), (out_ / "objects" / "3.txt").string(),
                    TrajectoryFormat::kKitti);
    testing::WriteText(out_ / "objects" / "index.csv",
                       "cluster,first_frame,last_frame,frames,landmarks\n3,2,4,3,1\n");
    testing::WriteText(out_ / "clusters.csv",
                       "landmark,cluster,first_frame,last_frame,x,y,z\n"
                       "7,0,0,5,1.5,-0.25,12\n"
                       "9,3,2,4,4.5,0,6.125\n");
  }
  fs::path clusters() const { return out_ / "clusters.csv"; }

  /// The InputError message ReadRunOutputs throws (the test fails when it throws none).
  std::string ErrorOf() {
    try {
      ReadRunOutputs(out_.string());
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  testing::TempDir tmp_;
  fs::path out_;
};

TEST_F(RunOutputsReader, ReadsBackEveryFileThePicturesNeed) {
  const RunOutputs o = ReadRunOutputs(out_.string());
  ASSERT_EQ(o.camera.size(), 6u);
  EXPECT_EQ(o.camera.frames, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(o.camera.poses[4].translation().isApprox(Eigen::Vector3d(0, 0, 4)));
  ASSERT_EQ(o.gt_camera.size(), 6u);
  EXPECT_DOUBLE_EQ(o.gt_camera.poses[1].translation().x(), 0.5);
  ASSERT_EQ(o.clusters.size(), 1u);
  ASSERT_EQ(o.clusters.count(3), 1u);
  // Cluster frames that do not start at 0 come back through the trajectory's frame index.
  EXPECT_EQ(o.clusters.at(3).frames, (std::vector<int>{2, 3, 4}));
  ASSERT_EQ(o.landmarks.size(), 2u);
  EXPECT_EQ(o.landmarks[1].id, 9);
  EXPECT_EQ(o.landmarks[1].cluster, 3);
  EXPECT_EQ(o.landmarks[1].first_frame, 2);
  EXPECT_EQ(o.landmarks[1].last_frame, 4);
  EXPECT_EQ(o.landmarks[1].p_world, Eigen::Vector3d(4.5, 0, 6.125));
  EXPECT_EQ(o.landmarks[0].p_world, Eigen::Vector3d(1.5, -0.25, 12));
}

TEST_F(RunOutputsReader, WithoutGroundTruthTheGroundTruthIsEmpty) {
  fs::remove(out_ / "camera_trajectory_gt.txt");
  EXPECT_TRUE(ReadRunOutputs(out_.string()).gt_camera.empty());
}

TEST_F(RunOutputsReader, MissingFolderIsNamed) {
  out_ = tmp_.path() / "nowhere";
  EXPECT_THAT(ErrorOf(), HasSubstr((tmp_.path() / "nowhere").string() + ": expected the output folder"));
}

TEST_F(RunOutputsReader, MissingCameraTrajectoryIsNamed) {
  fs::remove(out_ / "camera_trajectory.txt");
  EXPECT_THAT(ErrorOf(), HasSubstr((out_ / "camera_trajectory.txt").string() +
                                   ": missing: expected the camera trajectory"));
}

TEST_F(RunOutputsReader, MalformedCameraTrajectoryLineIsNamed) {
  testing::WriteText(out_ / "camera_trajectory.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0\n");
  EXPECT_THAT(ErrorOf(), HasSubstr((out_ / "camera_trajectory.txt").string() +
                                   ":2: expected 12 numbers"));
}

TEST_F(RunOutputsReader, NonNumericLandmarkCoordinateIsNamedWithItsLine) {
  testing::ReplaceLine(clusters(), "9,", "9,3,2,4,4.5,abc,6.125");
  EXPECT_THAT(ErrorOf(), HasSubstr(clusters().string() + ":3: 'y': expected a finite number, got 'abc'"));
}

TEST_F(RunOutputsReader, WrongFieldCountIsNamedWithItsLine) {
  testing::ReplaceLine(clusters(), "7,", "7,0,0,5,1.5");
  EXPECT_THAT(ErrorOf(), HasSubstr(clusters().string() + ":2: expected 7 comma-separated fields"));
}

TEST_F(RunOutputsReader, WrongHeaderIsNamed) {
  testing::ReplaceLine(clusters(), "landmark,", "id,cluster,x,y,z");
  EXPECT_THAT(ErrorOf(), HasSubstr(clusters().string() + ":1: expected the header"));
}

TEST_F(RunOutputsReader, LandmarkOfAClusterWithoutTrajectoryIsNamed) {
  testing::ReplaceLine(clusters(), "9,", "9,5,2,4,4.5,0,6.125");
  EXPECT_THAT(ErrorOf(), HasSubstr(clusters().string() + ":3: cluster 5 has no trajectory"));
}

TEST_F(RunOutputsReader, OutliersAreReadAndIdsBelowMinusOneAreNamed) {
  testing::ReplaceLine(clusters(), "7,", "7,-1,0,5,1.5,-0.25,12");
  const RunOutputs outputs = ReadRunOutputs(out_.string());
  ASSERT_EQ(outputs.landmarks.size(), 2u);
  EXPECT_EQ(outputs.landmarks[0].cluster, -1);
  testing::ReplaceLine(clusters(), "7,", "7,-2,0,5,1.5,-0.25,12");
  EXPECT_THAT(ErrorOf(), HasSubstr(clusters().string() + ":2: expected a cluster id >= -1"));
}

TEST_F(RunOutputsReader, MissingClusterTrajectoryIsNamed) {
  fs::remove(out_ / "objects" / "3.txt");
  EXPECT_THAT(ErrorOf(), HasSubstr((out_ / "objects" / "3.txt").string() + ": missing"));
}

TEST_F(RunOutputsReader, ClusterPoseCountDisagreeingWithTheIndexIsNamed) {
  testing::WriteText(out_ / "objects" / "index.csv",
                     "cluster,first_frame,last_frame,frames,landmarks\n3,2,4,5,1\n");
  EXPECT_THAT(ErrorOf(), HasSubstr((out_ / "objects" / "3.txt").string() + ": expected 5 poses"));
}

}  // namespace
}  // namespace cslam
