#pragma once
// PNG output that never leaves a truncated file behind.
#include <opencv2/core.hpp>
#include <string>

namespace cslam {

/// Encodes `image` (8-bit grey, BGR or BGRA) as PNG and writes it atomically to `path`,
/// creating missing folders. Throws OutputError naming the file when the image is empty,
/// cannot be encoded or the file cannot be written.
void WritePng(const cv::Mat& image, const std::string& path);

/// "<prefix>_NNNNNN.png" with the frame index zero-padded to six digits (render/ file names:
/// snapshot_000042.png, overlay_000042.png). Precondition: frame >= 0.
std::string FrameImageName(const std::string& prefix, int frame);

}  // namespace cslam
