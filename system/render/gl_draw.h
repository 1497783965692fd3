#pragma once
// Internal drawing helpers shared by the OpenGL renderers (fixed-function GL 1.x, which
// OSMesa's software rasteriser supports). Call them only while an OffscreenContext is current.
// The header is GL-free so it can be included anywhere; the GL calls live in gl_draw.cc.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "system/render/render_view.h"

namespace cslam::gl {

/// Clears to `background_rgb` and enables blending, smoothing and (optionally) depth testing.
void BeginFrame(const cv::Vec3b& background_rgb, bool depth_test);

/// Turns depth testing on or off for what is drawn next.
void EnableDepthTest(bool enable);

/// Sets up a 2-D pixel coordinate system: x right, y down, (u, v) = centre of pixel (u, v)
/// after read-back. Depth testing is disabled.
void UsePixelCoordinates(int width, int height);

/// Loads the projection and modelview of a perspective view.
void UseView(const RenderView& view);

/// Style of a polyline.
struct LineStyle {
  cv::Vec3b rgb{0, 0, 0};
  float alpha = 1.0f;
  float width_px = 1.0f;
  bool dashed = false;
  int dash_px = 8;  ///< length of a dash and of a gap, px
};

/// Draws a connected line through `points` (z is ignored in pixel coordinates).
void DrawLineStrip(const std::vector<Eigen::Vector3d>& points, const LineStyle& style);
/// Draws independent segments: points[0]-points[1], points[2]-points[3], ...
void DrawLines(const std::vector<Eigen::Vector3d>& points, const LineStyle& style);
/// Draws round points of one colour and size.
void DrawPoints(const std::vector<Eigen::Vector3d>& points, const cv::Vec3b& rgb, float size_px,
                float alpha = 1.0f);
/// Fills an axis-aligned rectangle in pixel coordinates.
void FillRect(double u0, double v0, double u1, double v1, const cv::Vec3b& rgb, float alpha);

}  // namespace cslam::gl
