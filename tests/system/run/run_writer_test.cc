#include "system/run/run_writer.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/system/kitti_fixtures.h"
#include "tests/support/poses.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

using testing::Translation;

// A window over `range` with a camera driving forward along z, landmarks 0..5 static and
// landmarks 6..9 on a body that slides sideways; `moving` false labels the body's landmarks
// static, as a later window does when it no longer sees them move.
MotionEstimate Window(FrameRange range, bool moving) {
  MotionEstimate e;
  e.range = range;
  const Pose window_from_world = Translation(0, 0, 1.0 * range.begin).inverse();
  for (int f = range.begin; f < range.end; ++f)
    e.world_from_cam.push_back(window_from_world * Translation(0, 0, 1.0 * f));
  for (int l = 0; l < 10; ++l) {
    const Eigen::Vector3d p(l % 3 - 1.0, l % 2 - 0.5, 10.0 + l);
    const bool on_body = l >= 6 && moving;
    e.landmark_cluster.push_back(on_body ? 1 : 0);
    e.landmark_in_cluster.push_back(on_body ? p : Eigen::Vector3d(window_from_world * p));
  }
  if (moving) {
    ClusterMotion m;
    m.cluster = 1;
    for (int f = range.begin; f < range.end; ++f) {
      m.frames.push_back(f);
      m.world_from_cluster.push_back(window_from_world * Translation(0.5 * f, 0, 0));
      m.cam_from_cluster.push_back(e.world_from_cam[f - range.begin].inverse() *
                                   m.world_from_cluster.back());
    }
    e.clusters.push_back(m);
  }
  return e;
}

TEST(RunWriter, LeavesOutAClusterWhoseLandmarksAllWentElsewhere) {
  PipelineResult result;
  MapStateOptions map_options;
  map_options.keep_lost_members = false;  // a window's static labels empty the cluster
  result.map = MapState(map_options);
  result.map.Integrate(Window({0, 10}, true));
  ASSERT_EQ(result.map.clusters().size(), 1u);
  ASSERT_EQ(result.map.clusters().begin()->second.num_landmarks, 4);

  testing::TempDir tmp("run_writer");
  RunInput input;
  input.timestamps.assign(15, 0.0);
  PipelineOptions options;
  const fs::path first = tmp.path() / "first";
  WriteRunOutputs(input, result, BuildRunTrajectories(result.map, input.timestamps), options,
                  first.string(), nullptr);
  const int id = result.map.clusters().begin()->first;
  EXPECT_TRUE(fs::exists(first / "objects" / (std::to_string(id) + ".txt")));
  EXPECT_EQ(testing::Lines(testing::ReadText(first / "objects" / "index.csv")).size(), 2u);

  // The next window sees the body's points holding still: they join the static world and the
  // map keeps the cluster's trajectory with no landmark left.
  result.map.Integrate(Window({5, 15}, false));
  ASSERT_EQ(result.map.clusters().count(id), 1u);
  ASSERT_EQ(result.map.clusters().at(id).num_landmarks, 0);
  const fs::path second = tmp.path() / "second";
  WriteRunOutputs(input, result, BuildRunTrajectories(result.map, input.timestamps), options,
                  second.string(), nullptr);
  EXPECT_FALSE(fs::exists(second / "objects" / (std::to_string(id) + ".txt")));
  EXPECT_EQ(testing::Lines(testing::ReadText(second / "objects" / "index.csv")).size(), 1u);
  EXPECT_TRUE(fs::exists(second / "camera_trajectory.txt"));
}

TEST(RunWriter, WindowsCsvHasOneRowPerWindowAndConfigYamlSaysWhereTheSettingsCameFrom) {
  PipelineResult result;
  result.map.Integrate(Window({0, 10}, true));
  WindowStats a;
  a.range = {0, 10};
  a.backend_ms = 12.5;
  a.integrate_ms = 0.25;
  a.clusters = 1;
  a.live_clusters = 1;
  a.live_landmarks = 10;
  WindowStats b = a;
  b.range = {5, 15};
  b.failed = true;
  b.adjustment_failed = true;
  result.windows = {a, b};
  testing::TempDir tmp("run_writer_windows");
  RunInput input;
  input.timestamps.assign(15, 0.0);
  PipelineOptions options;
  options.source = "built-in configs/kitti_raw.yaml";
  WriteRunOutputs(input, result, BuildRunTrajectories(result.map, input.timestamps), options,
                  tmp.path().string(), nullptr);
  const auto lines = testing::Lines(testing::ReadText(tmp.path() / "windows.csv"));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "first_frame,last_frame,failed,adjustment_failed,backend_ms,integrate_ms,"
                      "window_clusters,live_clusters,live_landmarks");
  EXPECT_EQ(lines[1], "0,9,0,0,12.5,0.25,1,1,10");
  EXPECT_EQ(lines[2], "5,14,1,1,12.5,0.25,1,1,10");
  EXPECT_EQ(testing::Lines(testing::ReadText(tmp.path() / "config.yaml"))[0],
            "# configuration: built-in configs/kitti_raw.yaml");
}

}  // namespace
}  // namespace cslam
