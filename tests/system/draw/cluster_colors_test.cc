#include "system/draw/cluster_colors.h"

#include <gtest/gtest.h>

#include "tests/system/image_test_util.h"

namespace cslam {
namespace {

TEST(ClusterColors, StaticAndUnclusteredAreGreysAndMovingClustersAreDistinct) {
  const cv::Vec3b s = ColorForCluster(0), u = ColorForCluster(-1);
  EXPECT_TRUE(s[0] == s[1] && s[1] == s[2]);
  EXPECT_TRUE(u[0] == u[1] && u[1] == u[2]);
  EXPECT_GT(u[0], s[0]);  // unclustered lighter than static
  const int n = ClusterPaletteSize();
  for (int a = 1; a <= n; ++a) {
    const cv::Vec3b ca = ColorForCluster(a);
    const int spread = std::max({ca[0], ca[1], ca[2]}) - std::min({ca[0], ca[1], ca[2]});
    EXPECT_GE(spread, 60) << "cluster " << a << " looks grey";
    for (int b = a + 1; b <= n; ++b)
      EXPECT_GE(testing::ColourDistance(ca, ColorForCluster(b)), 50) << a << " vs " << b;
  }
  EXPECT_EQ(ColorForCluster(1), ColorForCluster(1 + n));  // cycles
  EXPECT_EQ(TrajectoryColor(-1), cv::Vec3b(0, 0, 0));
  const cv::Vec3b rgb = ColorForCluster(2), bgr = BgrForCluster(2);
  EXPECT_EQ(rgb[0], bgr[2]);
  EXPECT_EQ(rgb[2], bgr[0]);
  EXPECT_NEAR(ColorForClusterUnit(2).x(), rgb[0] / 255.0f, 1e-6);
}

}  // namespace
}  // namespace cslam
