#include "system/render/offscreen_context.h"

#include <GL/osmesa.h>
#include <GL/gl.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/errors.h"

namespace cslam {

struct OffscreenContext::Impl {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> rgba;  // OSMesa renders straight into this buffer
  int width = 0;
  int height = 0;
};

OffscreenContext::OffscreenContext(int width, int height) : impl_(std::make_unique<Impl>()) {
  if (width <= 0 || height <= 0) {
    throw Error("offscreen rendering: image size must be positive, got " + std::to_string(width) +
                "x" + std::to_string(height));
  }
  impl_->width = width;
  impl_->height = height;
  impl_->context = OSMesaCreateContextExt(OSMESA_RGBA, /*depthBits=*/24, /*stencilBits=*/0,
                                          /*accumBits=*/0, /*sharelist=*/nullptr);
  if (impl_->context == nullptr) {
    throw Error(
        "offscreen rendering: OSMesa could not create an RGBA context with a 24-bit depth "
        "buffer (is libosmesa6 installed and working?)");
  }
  GLint max_width = 0, max_height = 0;
  impl_->rgba.assign(static_cast<std::size_t>(width) * height * 4, 0);
  try {
    MakeCurrent();
  } catch (...) {
    OSMesaDestroyContext(impl_->context);
    throw;
  }
  OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_width);
  OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_height);
  if ((max_width > 0 && width > max_width) || (max_height > 0 && height > max_height)) {
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(impl_->context);
    throw Error("offscreen rendering: " + std::to_string(width) + "x" + std::to_string(height) +
                " exceeds OSMesa's maximum " + std::to_string(max_width) + "x" +
                std::to_string(max_height));
  }
}

OffscreenContext::~OffscreenContext() {
  // Unbind first so the thread is not left pointing at a destroyed context.
  if (OSMesaGetCurrentContext() == impl_->context) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(impl_->context);
}

int OffscreenContext::width() const { return impl_->width; }
int OffscreenContext::height() const { return impl_->height; }

void OffscreenContext::MakeCurrent() {
  if (!OSMesaMakeCurrent(impl_->context, impl_->rgba.data(), GL_UNSIGNED_BYTE, impl_->width,
                         impl_->height)) {
    throw Error("offscreen rendering: OSMesaMakeCurrent failed for a " +
                std::to_string(impl_->width) + "x" + std::to_string(impl_->height) + " buffer");
  }
}

cv::Mat OffscreenContext::ReadPixels() const {
  glFinish();
  // OSMesa stores the bottom row first (GL convention); images are top row first.
  const cv::Mat rgba(impl_->height, impl_->width, CV_8UC4,
                     const_cast<unsigned char*>(impl_->rgba.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  cv::flip(bgr, bgr, 0);
  return bgr;
}

}  // namespace cslam
