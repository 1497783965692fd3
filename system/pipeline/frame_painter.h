#pragma once
// The frame-render point of a run: the pipeline prepares what a frame's pictures show from the
// map and hands it to a FramePainter, which draws and writes them. The pipeline links no
// renderer; `cslam run` and `cslam demo` give it the offscreen (OSMesa) one of
// system/run/offscreen_frame_painter.h.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "system/draw/render_scene.h"

namespace cslam {

/// What one frame's snapshot and overlay show: plain data, so the map may change afterwards.
struct FrameScene {
  int frame = 0;
  bool snapshot = false;  ///< render/snapshot_NNNNNN.png is due
  bool overlay = false;   ///< render/overlay_NNNNNN.png is due
  bool dense = false;     ///< the snapshot adds the frame's dense stereo cloud
  Pose world_from_cam = Pose::Identity();
  std::vector<RenderPoint> points;       ///< landmarks where they are at this frame
  std::vector<RenderTrajectory> recent;  ///< camera, ground truth and cluster paths
  std::vector<OverlayTrack> tracks;      ///< this frame's keypoints and their trails
};

/// Draws a frame's pictures and writes them into a run's render/ folder.
class FramePainter {
 public:
  virtual ~FramePainter() = default;
  /// Draws what `scene` asks for and writes snapshot_NNNNNN.png / overlay_NNNNNN.png into
  /// `render_dir`. `left`, `right`: the frame's images when the scene needs them (overlay,
  /// dense snapshot), else empty. Throws on failure. Called from one thread at a time.
  virtual void Paint(const FrameScene& scene, const StereoCamera& camera, const cv::Mat& left,
                     const cv::Mat& right, const std::string& render_dir) const = 0;
};

}  // namespace cslam
