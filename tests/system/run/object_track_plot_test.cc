// render/objects.png (system/run/object_track_plot.h): which lines it draws and what its legend
// says, and that each object's track is drawn in its id's colour.
#include "system/run/object_track_plot.h"

#include <gtest/gtest.h>

#include "system/draw/cluster_colors.h"
#include "system/render/trajectory_plot.h"
#include "tests/support/poses.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

using testing::Translation;

// The camera drives 2 m a frame along z over frames 0..19. Object 2 (frames 3..9) drives
// across at z 30, labelled as truth 8 over every frame; object 5 (frames 12..15) drives ahead
// at x -6, matched to nothing; truth 9 was never found.
RunOutputs Outputs() {
  RunOutputs o;
  for (int f = 0; f < 20; ++f) {
    o.camera.frames.push_back(f);
    o.camera.poses.push_back(Translation(0, 0, 2.0 * f));
    o.gt_objects[8].frames.push_back(f);
    o.gt_objects[8].poses.push_back(Translation(-10 + 1.5 * f, 0, 30.5));
    o.gt_objects[9].frames.push_back(f);
    o.gt_objects[9].poses.push_back(Translation(40, 0, 2.0 * f));
  }
  o.gt_camera = o.camera;
  for (int f = 3; f <= 9; ++f) {
    o.clusters[2].frames.push_back(f);
    o.clusters[2].poses.push_back(Translation(-10 + 1.5 * f, 0, 30));
  }
  for (int f = 12; f <= 15; ++f) {
    o.clusters[5].frames.push_back(f);
    o.clusters[5].poses.push_back(Translation(-6, 0, 40 + 3.0 * f));
  }
  o.gt_object_match[8] = {"Car", 2};
  o.gt_object_match[9] = {"Car", -1};
  return o;
}

RunMetrics Metrics() {
  RunMetrics m;
  RunMetrics::PerObject found;
  found.gt_object = 8;
  found.cluster = 2;
  found.me_r_deg = 0.4213;
  found.me_t_m = 0.0814;
  found.found = true;
  RunMetrics::PerObject missed;
  missed.gt_object = 9;
  m.objects.per_object = {found, missed};
  return m;
}

TEST(ObjectTrackPlot,
     CameraFaintOverTheObjectsFramesThenEachObjectByIdWithItsErrorsThenTruthDashed) {
  const RunMetrics metrics = Metrics();
  const auto lines = ObjectTrackPlotLines(Outputs(), &metrics);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0].cluster, kContextPath);
  EXPECT_EQ(lines[0].label, "camera, frames 3-15");
  EXPECT_EQ(lines[0].positions.size(), 13u);
  EXPECT_EQ(lines[1].cluster, 2);
  EXPECT_EQ(lines[1].label, "object 2 (Car), frames 3-9: ME_r 0.42 deg, ME_t 0.081 m");
  EXPECT_EQ(lines[2].cluster, 5);
  EXPECT_EQ(lines[2].label, "object 5, frames 12-15: no labelled object matched");
  // Truth 8 over object 2's frames only, in object 2's colour; one legend row for the dashes.
  EXPECT_TRUE(lines[3].dashed);
  EXPECT_EQ(lines[3].cluster, 2);
  EXPECT_TRUE(lines[3].label.empty());
  ASSERT_EQ(lines[3].positions.size(), 7u);
  EXPECT_EQ(lines[3].positions.front(), Eigen::Vector3d(-5.5, 0, 30.5));
  EXPECT_TRUE(lines[4].dashed);
  EXPECT_TRUE(lines[4].positions.empty());
  EXPECT_EQ(lines[5].label, "1 labelled object not found (truth id 9)");
  EXPECT_TRUE(lines[5].positions.empty());
}

TEST(ObjectTrackPlot, WithoutMetricsTheMatchOfTheIndexStillDrawsTheTruthAndNoErrorIsMadeUp) {
  const auto lines = ObjectTrackPlotLines(Outputs(), nullptr);
  ASSERT_GE(lines.size(), 4u);
  EXPECT_EQ(lines[1].label, "object 2 (Car), frames 3-9: truth id 8, no motion error");
  EXPECT_EQ(lines[2].label, "object 5, frames 12-15: no labelled object matched");
  EXPECT_TRUE(lines[3].dashed);
  EXPECT_EQ(lines[3].cluster, 2);
}

TEST(ObjectTrackPlot, ARunWithoutObjectsShowsTheCameraAndSaysSo) {
  RunOutputs o = Outputs();
  o.clusters.clear();
  o.gt_objects.clear();
  o.gt_object_match.clear();
  const auto lines = ObjectTrackPlotLines(o, nullptr);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].label, "camera, frames 0-19");
  EXPECT_EQ(lines[1].label, "no object reported");
}

TEST(ObjectTrackPlot, EachObjectsTrackIsDrawnInItsIdsColourAndTheCameraFaint) {
  const RunOutputs outputs = Outputs();
  const RunMetrics metrics = Metrics();
  const cv::Mat image = RenderObjectTrackPlot(outputs, &metrics);
  testing::MaybeSave(image, "object_track_plot.png");
  ASSERT_EQ(image.size(), cv::Size(1200, 900));
  const TopViewLayout layout =
      ComputeTopViewLayout(ObjectTrackPlotLines(outputs, &metrics), 1200, 900);
  // Object 5 along its whole track; object 2 where its truth (0.5 m away) does not cover it.
  EXPECT_GT(testing::SegmentCoverage(image, layout.ToPixel({-6, 0, 77}),
                                     layout.ToPixel({-6, 0, 84}), BgrForCluster(5), 40),
            0.9);
  EXPECT_GT(testing::SegmentCoverage(image, layout.ToPixel({-5, 0, 30}), layout.ToPixel({3, 0, 30}),
                                     BgrForCluster(2), 40),
            0.9);
  const cv::Vec3b faint = TrajectoryColor(kContextPath);
  EXPECT_GT(testing::SegmentCoverage(image, layout.ToPixel({0, 0, 8}), layout.ToPixel({0, 0, 28}),
                                     {faint[2], faint[1], faint[0]}, 30),
            0.9);
  // The camera is no longer drawn black here.
  EXPECT_LT(testing::SegmentCoverage(image, layout.ToPixel({0, 0, 8}), layout.ToPixel({0, 0, 28}),
                                     {0, 0, 0}, 60),
            0.1);
}

}  // namespace
}  // namespace cslam
