#include "system/render/gl_draw.h"

#include <GL/gl.h>

#include <algorithm>

namespace cslam::gl {
namespace {

void SetColor(const cv::Vec3b& rgb, float alpha) {
  glColor4f(rgb[0] / 255.0f, rgb[1] / 255.0f, rgb[2] / 255.0f, alpha);
}

void LoadMatrix(GLenum mode, const Eigen::Matrix4d& m) {
  glMatrixMode(mode);
  glLoadMatrixd(m.data());  // Eigen's default storage is column-major, as GL expects
}

void DrawPrimitive(GLenum mode, const std::vector<Eigen::Vector3d>& points,
                   const LineStyle& style) {
  if (points.size() < 2) return;
  SetColor(style.rgb, style.alpha);
  glLineWidth(style.width_px);
  if (style.dashed) {
    // Stipple is a 16-bit pattern repeated `factor` times per bit: 8 bits on, 8 off.
    glEnable(GL_LINE_STIPPLE);
    glLineStipple(std::clamp(style.dash_px / 8, 1, 256), 0x00FF);
  }
  glBegin(mode);
  for (const auto& p : points) glVertex3d(p.x(), p.y(), p.z());
  glEnd();
  if (style.dashed) glDisable(GL_LINE_STIPPLE);
}

}  // namespace

void BeginFrame(const cv::Vec3b& background_rgb, bool depth_test) {
  glClearColor(background_rgb[0] / 255.0f, background_rgb[1] / 255.0f,
               background_rgb[2] / 255.0f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_LINE_SMOOTH);
  glEnable(GL_POINT_SMOOTH);
  glHint(GL_LINE_SMOOTH_HINT, GL_NICEST);
  glHint(GL_POINT_SMOOTH_HINT, GL_NICEST);
  EnableDepthTest(depth_test);
}

void EnableDepthTest(bool enable) {
  if (enable) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
}

void UsePixelCoordinates(int width, int height) {
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  // top = 0 so v grows downwards after the read-back flip; +0.5 moves vertices to pixel centres.
  glOrtho(0.0, width, height, 0.0, -1.0, 1.0);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glTranslated(0.5, 0.5, 0.0);
  glDisable(GL_DEPTH_TEST);
}

void UseView(const RenderView& view) {
  LoadMatrix(GL_PROJECTION, view.GlProjection());
  LoadMatrix(GL_MODELVIEW, view.GlModelView());
}

void DrawLineStrip(const std::vector<Eigen::Vector3d>& points, const LineStyle& style) {
  DrawPrimitive(GL_LINE_STRIP, points, style);
}

void DrawLines(const std::vector<Eigen::Vector3d>& points, const LineStyle& style) {
  DrawPrimitive(GL_LINES, points, style);
}

void DrawPoints(const std::vector<Eigen::Vector3d>& points, const cv::Vec3b& rgb, float size_px,
                float alpha) {
  if (points.empty()) return;
  SetColor(rgb, alpha);
  glPointSize(size_px);
  glBegin(GL_POINTS);
  for (const auto& p : points) glVertex3d(p.x(), p.y(), p.z());
  glEnd();
}

void FillRect(double u0, double v0, double u1, double v1, const cv::Vec3b& rgb, float alpha) {
  SetColor(rgb, alpha);
  glBegin(GL_QUADS);
  glVertex2d(u0, v0);
  glVertex2d(u1, v0);
  glVertex2d(u1, v1);
  glVertex2d(u0, v1);
  glEnd();
}

}  // namespace cslam::gl
