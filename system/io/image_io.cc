#include "system/io/image_io.h"

#include <cstdio>
#include <vector>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/io/png_codec.h"

namespace cslam {

void WritePng(const cv::Mat& image, const std::string& path) {
  if (image.empty()) throw OutputError(path, "refusing to write an empty image");
  std::vector<unsigned char> bytes;
  try {
    bytes = EncodePng(image);
  } catch (const std::exception& e) {
    throw OutputError(path, e.what());
  }
  WriteFileAtomically(path, [&bytes](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

std::string FrameImageName(const std::string& prefix, int frame) {
  CSLAM_CHECK(frame >= 0, "frame index must not be negative");
  char digits[16];
  std::snprintf(digits, sizeof(digits), "%06d", frame);
  return prefix + "_" + digits + ".png";
}

}  // namespace cslam
