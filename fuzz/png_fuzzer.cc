// Fuzz target: a PNG file through ReadPng (the fast path, then libpng) and, differentially,
// the fast path against libpng alone: where both decode, the pixels must be the same.
#include <cstdlib>
#include <span>

#include <opencv2/core.hpp>

#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/io/png_codec.h"
#include "system/io/png_fast_decode.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cslam::fuzz::WriteInput(data, size, "frame.png");
  const std::span<const unsigned char> bytes(data, size);
  static cslam::PngFastDecoder fast;
  for (cslam::PngPixels pixels : {cslam::PngPixels::kGrey8, cslam::PngPixels::kGreyAnyDepth,
                                  cslam::PngPixels::kUnchanged}) {
    try {
      (void)cslam::ReadPng(path, pixels);
    } catch (const cslam::Error&) {
    }
    cv::Mat quick;
    if (fast.Decode(bytes, pixels, &quick) != cslam::PngFastResult::kDecoded) continue;
    cv::Mat reference;
    try {
      reference = cslam::DecodePngWithLibpng(bytes, pixels, path);
    } catch (const cslam::Error&) {
      continue;  // libpng is stricter about some chunk orders; ReadPng then reports its error
    }
    if (quick.type() != reference.type() || quick.size() != reference.size() ||
        cv::norm(quick, reference, cv::NORM_INF) != 0)
      std::abort();  // the fast path gave other pixels than libpng
  }
  return 0;
}
