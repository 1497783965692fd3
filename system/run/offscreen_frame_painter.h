#pragma once
// The FramePainter of `cslam run` and `cslam demo`: snapshots drawn offscreen with OSMesa
// (system/render/snapshot_renderer.h) and keypoint overlays drawn with OpenCV.
#include "system/pipeline/frame_painter.h"
#include "system/render/snapshot_renderer.h"

namespace cslam {

/// Draws with SnapshotRenderer / RenderDenseSnapshot and RenderOverlay and writes PNGs.
class OffscreenFramePainter final : public FramePainter {
 public:
  explicit OffscreenFramePainter(SnapshotOptions options = {}) : options_(options) {}
  void Paint(const FrameScene& scene, const StereoCamera& camera, const cv::Mat& left,
             const cv::Mat& right, const std::string& render_dir) const override;

 private:
  SnapshotOptions options_;
};

}  // namespace cslam
