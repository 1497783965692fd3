#include "system/draw/overlay_renderer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "system/draw/annotate.h"
#include "system/draw/cluster_colors.h"

namespace cslam {
namespace {

constexpr int kTrailThicknessPx = 2;
constexpr int kDotRadiusPx = 3;
// A dark ring keeps grey (static) dots visible on a grey image.
constexpr int kOutlinePx = 1;
const cv::Scalar kOutlineBgr(20, 20, 20);
constexpr int kSubpixelBits = 4;  // cv drawing with 1/16 px precision
constexpr double kSubpixelScale = 1 << kSubpixelBits;

cv::Point Fixed(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * kSubpixelScale)),
          static_cast<int>(std::lround(p.y() * kSubpixelScale))};
}

cv::Scalar Bgr(int cluster) {
  const cv::Vec3b c = BgrForCluster(cluster);
  return cv::Scalar(c[0], c[1], c[2]);
}

/// Draw order: unclustered, static, then moving clusters on top.
int Layer(int cluster) { return cluster < 0 ? 0 : (cluster == 0 ? 1 : 2); }

}  // namespace

cv::Mat RenderOverlay(const cv::Mat& left_grey, const std::vector<OverlayTrack>& tracks) {
  if (left_grey.empty() || left_grey.depth() != CV_8U ||
      (left_grey.channels() != 1 && left_grey.channels() != 3)) {
    throw InputError("overlay", "left image must be a non-empty 8-bit grey or BGR image");
  }
  cv::Mat image;
  if (left_grey.channels() == 1)
    cv::cvtColor(left_grey, image, cv::COLOR_GRAY2BGR);
  else
    image = left_grey.clone();

  std::vector<const OverlayTrack*> order;
  order.reserve(tracks.size());
  for (const auto& t : tracks)
    if (!t.trail.empty()) order.push_back(&t);
  std::stable_sort(order.begin(), order.end(), [](const OverlayTrack* a, const OverlayTrack* b) {
    return Layer(a->cluster) < Layer(b->cluster);
  });
  for (const OverlayTrack* t : order) {
    const cv::Scalar colour = Bgr(t->cluster);
    for (std::size_t i = 1; i < t->trail.size(); ++i) {
      if (!t->trail[i - 1].allFinite() || !t->trail[i].allFinite()) continue;
      cv::line(image, Fixed(t->trail[i - 1]), Fixed(t->trail[i]), colour, kTrailThicknessPx,
               cv::LINE_AA, kSubpixelBits);
    }
    const Eigen::Vector2d& now = t->trail.back();
    if (!now.allFinite()) continue;
    cv::circle(image, Fixed(now), (kDotRadiusPx + kOutlinePx) << kSubpixelBits, kOutlineBgr,
               cv::FILLED, cv::LINE_AA, kSubpixelBits);
    cv::circle(image, Fixed(now), kDotRadiusPx << kSubpixelBits, colour, cv::FILLED, cv::LINE_AA,
               kSubpixelBits);
  }
  return image;
}

void DrawOverlayLegend(cv::Mat& image, const std::vector<OverlayTrack>& tracks) {
  std::map<int, int> counts;
  for (const OverlayTrack& t : tracks) ++counts[std::max(t.cluster, -1)];
  std::vector<LegendEntry> legend;
  for (const auto& [cluster, n] : counts) {
    const std::string name = cluster == 0 ? "static" : cluster < 0 ? "outlier" : "object " + std::to_string(cluster);
    legend.push_back({name + " (" + std::to_string(n) + ")", ColorForCluster(cluster), LegendMarker::kDot});
  }
  DrawLegend(image, legend, {8, 8});
}

}  // namespace cslam
