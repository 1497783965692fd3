#pragma once
// An offscreen OpenGL context rendered by Mesa's software rasteriser (OSMesa): no X server and
// no GPU needed, so pictures can be drawn on a headless machine or in CI.
//
// Thread safety: a context is current on the thread that constructed it (or last called
// MakeCurrent). Use one context from one thread at a time; separate contexts on separate
// threads are independent.
#include <memory>
#include <opencv2/core.hpp>

namespace cslam {

/// RAII OSMesa context with an RGBA colour buffer and a 24-bit depth buffer. The GL calls a
/// renderer makes between construction and ReadPixels() draw into this context. Legacy
/// fixed-function GL (1.x) is available.
class OffscreenContext {
 public:
  /// Creates a width x height context and makes it current on the calling thread. Throws
  /// cslam::Error with the reason when the size is invalid or OSMesa cannot create or bind
  /// the context.
  OffscreenContext(int width, int height);
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  int width() const;
  int height() const;

  /// Binds the context to the calling thread (needed only when another thread or context was
  /// used since construction). Throws cslam::Error when OSMesa refuses.
  void MakeCurrent();

  /// Finishes rendering and returns the colour buffer as an 8-bit BGR image, top row first.
  cv::Mat ReadPixels() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cslam
