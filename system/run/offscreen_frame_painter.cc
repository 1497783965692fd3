#include "system/run/offscreen_frame_painter.h"

#include "system/draw/annotate.h"
#include "system/draw/overlay_renderer.h"
#include "system/io/image_io.h"
#include "system/run/final_pictures.h"

namespace cslam {

void OffscreenFramePainter::Paint(const FrameScene& scene, const StereoCamera& camera,
                                  const cv::Mat& left, const cv::Mat& right,
                                  const std::string& render_dir) const {
  if (scene.snapshot) {
    cv::Mat picture =
        scene.dense ? RenderDenseSnapshot(scene.points, scene.world_from_cam, camera, scene.recent,
                                          left, right, options_)
                    : RenderSnapshot(scene.points, scene.world_from_cam, camera, scene.recent,
                                     options_);
    PutCornerLabel(picture, "frame " + std::to_string(scene.frame) + ", online state");
    WritePng(picture, NumberedPngPath(render_dir, "snapshot", scene.frame));
  }
  if (scene.overlay) {
    cv::Mat picture = RenderOverlay(left, scene.tracks);
    DrawOverlayLegend(picture, scene.tracks);
    PutCornerLabel(picture, "frame " + std::to_string(scene.frame) + ", online state");
    WritePng(picture, NumberedPngPath(render_dir, "overlay", scene.frame));
  }
}

}  // namespace cslam
