#include "system/draw/cluster_colors.h"

#include <array>

namespace cslam {
namespace {

// Tableau-10 without its grey, then darker/brighter companions; no greys or near-black so a
// moving cluster is never confused with the static background or the camera.
constexpr std::array<std::array<unsigned char, 3>, 14> kPalette = {{
    {31, 119, 180},   // blue
    {255, 127, 14},   // orange
    {44, 160, 44},    // green
    {214, 39, 40},    // red
    {148, 103, 189},  // purple
    {140, 86, 75},    // brown
    {227, 119, 194},  // pink
    {188, 189, 34},   // olive
    {23, 190, 207},   // cyan
    {0, 0, 160},      // navy
    {255, 200, 0},    // gold
    {0, 110, 100},    // teal
    {128, 0, 40},     // maroon
    {230, 0, 230},    // magenta
}};

constexpr unsigned char kStaticGrey = 128;
constexpr unsigned char kUnclusteredGrey = 200;

}  // namespace

cv::Vec3b ColorForCluster(int cluster) {
  if (cluster < 0) return {kUnclusteredGrey, kUnclusteredGrey, kUnclusteredGrey};
  if (cluster == 0) return {kStaticGrey, kStaticGrey, kStaticGrey};
  const auto& c = kPalette[static_cast<std::size_t>(cluster - 1) % kPalette.size()];
  return {c[0], c[1], c[2]};
}

cv::Vec3b BgrForCluster(int cluster) {
  const cv::Vec3b rgb = ColorForCluster(cluster);
  return {rgb[2], rgb[1], rgb[0]};
}

Eigen::Vector3f ColorForClusterUnit(int cluster) {
  const cv::Vec3b rgb = ColorForCluster(cluster);
  return Eigen::Vector3f(rgb[0], rgb[1], rgb[2]) / 255.0f;
}

cv::Vec3b TrajectoryColor(int cluster) {
  if (cluster == kUndrawnClusters) return {150, 150, 150};
  if (cluster == kContextPath) return {170, 170, 170};
  if (cluster < 0) return {0, 0, 0};
  return ColorForCluster(cluster);
}

int ClusterPaletteSize() { return static_cast<int>(kPalette.size()); }

}  // namespace cslam
