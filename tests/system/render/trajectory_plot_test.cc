#include "system/render/trajectory_plot.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "system/draw/cluster_colors.h"
#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

using testing::ColourNear;

std::vector<RenderTrajectory> Scene() {
  RenderTrajectory camera{"camera", {}, -1, false};
  RenderTrajectory truth{"ground truth cluster 2", {}, 2, true};
  RenderTrajectory cluster{"cluster 1", {}, 1, false};
  for (int i = 0; i <= 50; ++i) {
    camera.positions.emplace_back(0.0, 0.0, 1.0 * i);  // straight ahead, 50 m
    truth.positions.emplace_back(6.0, 0.0, 0.8 * i);   // parallel, 6 m to the right
    cluster.positions.emplace_back(-5.0 + 0.1 * i, 0.0, 10.0 + 0.5 * i);
  }
  return {truth, camera, cluster};
}

/// Fraction of 1-px steps along the segment a-b (world) where the colour shows.
double Coverage(const cv::Mat& image, const TopViewLayout& layout, const Eigen::Vector3d& a,
                const Eigen::Vector3d& b, const cv::Vec3b& bgr, int tolerance) {
  return testing::SegmentCoverage(image, layout.ToPixel(a), layout.ToPixel(b), bgr, tolerance);
}

TEST(TrajectoryPlot, LayoutFitsAllPositionsWithEqualAxes) {
  const auto scene = Scene();
  const TopViewLayout layout = ComputeTopViewLayout(scene, 800, 600);
  for (const auto& t : scene)
    for (const auto& p : t.positions) {
      const Eigen::Vector2d px = layout.ToPixel(p);
      EXPECT_GE(px.x(), layout.plot_left);
      EXPECT_LE(px.x(), layout.plot_right);
      EXPECT_GE(px.y(), layout.plot_top);
      EXPECT_LE(px.y(), layout.plot_bottom);
    }
  // z forward points up in the picture, x to the right.
  EXPECT_LT(layout.ToPixel({0, 0, 10}).y(), layout.ToPixel({0, 0, 0}).y());
  EXPECT_GT(layout.ToPixel({1, 0, 0}).x(), layout.ToPixel({0, 0, 0}).x());
  // The 50 m extent fills most of the plot height.
  EXPECT_GT(50.0 * layout.scale_px_per_m, 0.8 * (layout.plot_bottom - layout.plot_top));
}

TEST(TrajectoryPlot, DrawsTheCameraSolidBlackAndGroundTruthDashed) {
  const auto scene = Scene();
  const cv::Mat image = RenderTrajectoryTopView(scene, 800, 600);
  testing::MaybeSave(image, "trajectory.png");
  ASSERT_EQ(image.size(), cv::Size(800, 600));
  const TopViewLayout layout = ComputeTopViewLayout(scene, 800, 600);

  // Every camera position has black under it (anti-aliased 2 px line: allow dark grey).
  for (const auto& p : scene[1].positions)
    EXPECT_TRUE(ColourNear(image, layout.ToPixel(p), {0, 0, 0}, 1, 70)) << p.transpose();
  // Continuous along the whole camera path (away from the start marker).
  EXPECT_GT(Coverage(image, layout, {0, 0, 2}, {0, 0, 48}, {0, 0, 0}, 70), 0.98);
  // The solid cluster line is continuous in its colour...
  EXPECT_GT(Coverage(image, layout, scene[2].positions[5], scene[2].positions[45],
                     BgrForCluster(1), 60),
            0.98);
  // ...and the ground truth is dashed: its colour shows on part of the path only.
  const double dashed = Coverage(image, layout, {6, 0, 2}, {6, 0, 38}, BgrForCluster(2), 60);
  EXPECT_GT(dashed, 0.3);
  EXPECT_LT(dashed, 0.8);
  // Nothing drawn in the colour of a cluster that is not in the scene.
  EXPECT_EQ(testing::CountColour(image, BgrForCluster(4), 30), 0);
}

TEST(TrajectoryPlot, ANonFinitePositionBreaksTheLine) {
  auto scene = Scene();
  auto& cluster = scene[2].positions;  // from (-5, 10) to (0, 35)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k : {24, 25, 26}) cluster[k] = Eigen::Vector3d::Constant(nan);
  const cv::Mat image = RenderTrajectoryTopView(scene, 800, 600);
  const TopViewLayout layout = ComputeTopViewLayout(scene, 800, 600);
  const cv::Vec3b colour = BgrForCluster(1);
  EXPECT_GT(Coverage(image, layout, cluster[5], cluster[22], colour, 60), 0.98);
  EXPECT_GT(Coverage(image, layout, cluster[28], cluster[45], colour, 60), 0.98);
  // Between the last point before the break and the first after (2 m apart): nothing, away
  // from the pieces' ends.
  const Eigen::Vector3d a = cluster[23], b = cluster[27];
  EXPECT_LT(Coverage(image, layout, a + 0.3 * (b - a), a + 0.7 * (b - a), colour, 60), 0.2);
}

TEST(TrajectoryPlot, LegendOfSixtyClustersStaysInsideThePlot) {
  // An online map easily holds dozens of clusters; the legend used to run off the top of
  // the image over the title.
  std::vector<RenderTrajectory> scene{{"camera", {}, -1, false}};
  for (int i = 0; i <= 50; ++i) scene[0].positions.emplace_back(0.0, 0.0, 1.0 * i);
  for (int c = 1; c <= 60; ++c) {
    RenderTrajectory t{"cluster " + std::to_string(c), {}, c, false};
    for (int i = 0; i <= 5; ++i) t.positions.emplace_back(20.0, 0.0, 40.0 + 0.1 * i);
    scene.push_back(t);
  }
  const cv::Mat image = RenderTrajectoryTopView(scene, 800, 600);
  testing::MaybeSave(image, "trajectory_many.png");
  // The title band above the plot and the axis band below it hold no legend swatch of any
  // cluster colour.
  const cv::Mat top = image(cv::Rect(0, 0, image.cols, 20));
  const cv::Mat bottom = image(cv::Rect(0, image.rows - 20, image.cols, 20));
  for (int c = 1; c <= 60; ++c) {
    EXPECT_EQ(testing::CountColour(top, BgrForCluster(c), 20), 0) << "cluster " << c;
    EXPECT_EQ(testing::CountColour(bottom, BgrForCluster(c), 20), 0) << "cluster " << c;
  }
  // The first clusters are still named in the legend (their colour shows outside the data).
  EXPECT_GT(testing::CountColour(image, BgrForCluster(1), 20), 20);
}

/// A drive like KITTI raw 0005's: a long narrow camera path with short cluster paths beside
/// it from start to end, and legend labels wide enough that every plot corner holds data.
std::vector<RenderTrajectory> CrowdedDrive() {
  std::vector<RenderTrajectory> scene{{"camera", {}, -1, false}};
  for (int i = 0; i <= 100; ++i) scene[0].positions.emplace_back(0.0, 0.0, 1.0 * i);
  for (int c = 1; c <= 12; ++c) {
    RenderTrajectory t{"cluster " + std::to_string(c) + ": a label as wide as the small-cluster note of a long drive",
                       {},
                       c, false};
    for (int i = 0; i <= 4; ++i) t.positions.emplace_back(-20.0, 0.0, 8.0 * c - 4.0 + i);
    scene.push_back(t);
  }
  return scene;
}

TEST(TrajectoryPlot, LegendMovesBesideThePlotWhenEveryCornerHoldsData) {
  // The legend used to go to the least covered corner even when that hid part of the camera
  // path.
  const auto scene = CrowdedDrive();
  const cv::Mat image = RenderTrajectoryTopView(scene);
  testing::MaybeSave(image, "trajectory_crowded.png");
  const TopViewLayout layout = ComputeTopViewLayout(scene, 1200, 900);
  const cv::Rect plot(layout.plot_left, layout.plot_top, layout.plot_right - layout.plot_left,
                      layout.plot_bottom - layout.plot_top);
  EXPECT_TRUE((layout.legend & plot).empty()) << layout.legend;
  EXPECT_TRUE((layout.legend & cv::Rect(0, 0, 1200, 900)) == layout.legend) << layout.legend;
  // Every position is drawn in its own colour: nothing lies under the legend.
  for (const auto& p : scene[0].positions)
    EXPECT_TRUE(ColourNear(image, layout.ToPixel(p), {0, 0, 0}, 1, 70)) << p.transpose();
  for (int c = 1; c <= 12; ++c)
    for (const auto& p : scene[c].positions)
      EXPECT_TRUE(ColourNear(image, layout.ToPixel(p), BgrForCluster(c), 1, 60))
          << "cluster " << c << " at " << p.transpose();
  // The legend column costs the drawing no scale: the path's height still sets it.
  auto unlabelled = scene;
  for (auto& t : unlabelled) t.label.clear();
  EXPECT_NEAR(layout.scale_px_per_m, ComputeTopViewLayout(unlabelled, 1200, 900).scale_px_per_m,
              1e-9);
}

TEST(TrajectoryPlot, WideDrawingKeepsItsScaleWithTheLegendInsideThePlot) {
  // Turned sideways the same drive fills the plot's width; a legend column would shrink it
  // by more than a quarter, so the legend stays in the least covered corner.
  auto scene = CrowdedDrive();
  for (auto& t : scene)
    for (auto& p : t.positions) p = Eigen::Vector3d(p.z(), 0.0, -p.x());
  const TopViewLayout layout = ComputeTopViewLayout(scene, 1200, 900);
  const cv::Rect plot(layout.plot_left, layout.plot_top, layout.plot_right - layout.plot_left,
                      layout.plot_bottom - layout.plot_top);
  EXPECT_TRUE((layout.legend & plot) == layout.legend) << layout.legend;
  auto unlabelled = scene;
  for (auto& t : unlabelled) t.label.clear();
  EXPECT_NEAR(layout.scale_px_per_m, ComputeTopViewLayout(unlabelled, 1200, 900).scale_px_per_m,
              1e-9);
}

TEST(TrajectoryPlot, IsDeterministicAndCanRunOnTwoThreadsAtOnce) {
  const auto scene = Scene();
  const cv::Mat reference = RenderTrajectoryTopView(scene, 500, 400);
  cv::Mat a, b;
  std::thread ta([&] { a = RenderTrajectoryTopView(scene, 500, 400); });
  std::thread tb([&] { b = RenderTrajectoryTopView(scene, 500, 400); });
  ta.join();
  tb.join();
  EXPECT_EQ(cv::norm(a, reference, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(b, reference, cv::NORM_INF), 0.0);
}

// Real KITTI odometry ground truth (dashed) beside an estimate that drifts sideways: the plot
// keeps both on the page and the estimate is black along its whole length.
TEST(TrajectoryPlot, KittiOdometryGroundTruthAndADriftingEstimate) {
  const char* env = std::getenv("CSLAM_SHARED_DATA");  // overrides the build-time path
  const std::string file =
      std::string(env ? env : CSLAM_SHARED_DATA_DIR) + "/kitti_odometry/poses/clip_a.txt";
  std::ifstream in(file);
  if (!in) GTEST_SKIP() << "KITTI odometry poses not found: " << file;
  RenderTrajectory truth{"ground truth", {}, -1, true};
  RenderTrajectory estimate{"camera", {}, -1, false};
  RenderTrajectory van{"cluster 1 (van)", {}, 1, false};
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double m[12];
    for (double& v : m) fields >> v;
    const Eigen::Vector3d p(m[3], m[7], m[11]);
    const double k = static_cast<double>(truth.positions.size());
    truth.positions.push_back(p);
    estimate.positions.push_back(p + Eigen::Vector3d(0.04 * k, 0.0, -0.01 * k));
    van.positions.push_back(p + Eigen::Vector3d(-3.0, 0.0, 12.0 + 0.3 * k));
  }
  ASSERT_EQ(truth.positions.size(), 51u);
  const std::vector<RenderTrajectory> scene = {truth, estimate, van};
  const cv::Mat image = RenderTrajectoryTopView(scene);
  testing::MaybeSave(image, "trajectory_kitti.png");
  const TopViewLayout layout = ComputeTopViewLayout(scene, 1200, 900);
  for (const auto& p : estimate.positions)
    EXPECT_TRUE(ColourNear(image, layout.ToPixel(p), {0, 0, 0}, 1, 70)) << p.transpose();
  for (const auto& p : van.positions)
    EXPECT_TRUE(ColourNear(image, layout.ToPixel(p), BgrForCluster(1), 1, 60)) << p.transpose();
}

TEST(TrajectoryPlot, EmptyInputGivesAnEmptyGridNotACrash) {
  const cv::Mat image = RenderTrajectoryTopView({}, 400, 300);
  ASSERT_EQ(image.size(), cv::Size(400, 300));
  // Mostly white, but labels and grid are there.
  const int white = testing::CountColour(image, {255, 255, 255}, 0);
  EXPECT_GT(white, 400 * 300 / 2);
  EXPECT_LT(white, 400 * 300);
}

}  // namespace
}  // namespace cslam
