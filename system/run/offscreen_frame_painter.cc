#include "system/run/offscreen_frame_painter.h"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include "system/draw/overlay_renderer.h"
#include "system/io/image_io.h"

namespace cslam {

namespace {

std::string Numbered(const std::string& dir, const char* stem, int frame) {
  std::ostringstream name;
  name << stem << "_" << std::setw(6) << std::setfill('0') << frame << ".png";
  return (std::filesystem::path(dir) / name.str()).string();
}

}  // namespace

void OffscreenFramePainter::Paint(const FrameScene& scene, const StereoCamera& camera,
                                  const cv::Mat& left, const cv::Mat& right,
                                  const std::string& render_dir) const {
  if (scene.snapshot) {
    const cv::Mat picture =
        scene.dense ? RenderDenseSnapshot(scene.points, scene.world_from_cam, camera, scene.recent,
                                          left, right, options_)
                    : RenderSnapshot(scene.points, scene.world_from_cam, camera, scene.recent,
                                     options_);
    WritePng(picture, Numbered(render_dir, "snapshot", scene.frame));
  }
  if (scene.overlay) WritePng(RenderOverlay(left, scene.tracks), Numbered(render_dir, "overlay", scene.frame));
}

}  // namespace cslam
