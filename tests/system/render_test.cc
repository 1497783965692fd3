#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "system/cluster_colors.h"
#include "system/image_io.h"
#include "system/offscreen_context.h"
#include "system/trajectory_plot.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

TEST(TrajectoryPlot, Smoke) {
  std::vector<RenderTrajectory> t;
  RenderTrajectory cam{"camera", {}, -1, false};
  RenderTrajectory gt{"ground truth", {}, -1, true};
  RenderTrajectory c1{"cluster 1", {}, 1, false};
  RenderTrajectory c2{"cluster 2", {}, 2, false};
  for (int i = 0; i <= 100; ++i) {
    const double s = i * 0.6;
    cam.positions.emplace_back(3.0 * std::sin(s / 20.0), 0.0, s);
    gt.positions.emplace_back(3.0 * std::sin(s / 20.0) + 0.8, 0.0, s * 1.02);
    c1.positions.emplace_back(-4.0 + 0.02 * s, 0.0, 10 + 0.9 * s);
    c2.positions.emplace_back(6.0 - 0.1 * s, 0.0, 20 + 0.3 * s);
  }
  const cv::Mat img = RenderTrajectoryTopView({gt, cam, c1, c2});
  WritePng(img, "/tmp/cslam_render/trajectory.png");
}

}  // namespace
}  // namespace cslam
