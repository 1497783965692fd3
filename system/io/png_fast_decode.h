#pragma once
// A PNG decoder for the layouts cslam reads in bulk (the dataset readers: 8-bit grey KITTI and
// EuRoC frames), with libdeflate in place of zlib and its own row unfiltering: libpng spent
// about a fifth of a KITTI run's CPU inflating and unfiltering, on the reader thread that
// shares the two cores with the frontend. It handles non-interlaced 8- and 16-bit grey, RGB
// and RGBA files whose pixels libpng (png_codec.h) would only copy, chop to 8 bits, byte-swap
// or reorder to BGR(A), and leaves everything else to libpng: palettes, low bit depths,
// interlacing, transparency and colour chunks, colour → grey (libpng's fixed-point weights).
// A file it finds damaged is left to libpng too, so what a corrupt file gives (the error, or
// libpng's leniency, e.g. towards a bad CRC on an ancillary chunk) is the same as before.
#include <opencv2/core.hpp>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "system/io/png_codec.h"

struct libdeflate_decompressor;

namespace cslam {

/// DEFLATE turns at most two bits into 258 bytes (a longest match with one-bit codes): a header
/// claiming more pixels than this many times the compressed size is damaged or hostile, and is
/// refused before its buffer is allocated (by this decoder and by png_codec's libpng path).
inline constexpr std::size_t kPngMaxInflateRatio = 1032;

/// The big-endian 32-bit integer at `p` (PNG's chunk lengths, CRCs and header fields).
std::uint32_t PngBigEndian32(const unsigned char* p);

/// What PngFastDecoder::Decode did with a file.
enum class PngFastResult {
  kDecoded,      ///< the image holds the pixels libpng gives for the same request
  kUnsupported,  ///< a layout, chunk or conversion left to libpng
  kCorrupt,      ///< a bad signature, chunk, CRC, zlib stream, data size or filter type
};

/// Decodes whole PNG files in memory; keeps its buffers between calls. One per thread.
class PngFastDecoder {
 public:
  PngFastDecoder();
  ~PngFastDecoder();
  PngFastDecoder(const PngFastDecoder&) = delete;
  PngFastDecoder& operator=(const PngFastDecoder&) = delete;

  /// Decodes the PNG file `bytes` into `image` as ReadPng does for `pixels`, when the layout
  /// is one it handles and every check passes; otherwise returns why not, `image` unspecified.
  PngFastResult Decode(std::span<const unsigned char> bytes, PngPixels pixels, cv::Mat* image);

 private:
  libdeflate_decompressor* inflater_ = nullptr;
  std::vector<unsigned char> idat_;      // IDAT payloads joined, when the file splits them
  std::vector<unsigned char> filtered_;  // inflated rows, each after its filter-type byte
  std::vector<unsigned char> zero_row_;  // the row "above" the first one
};

}  // namespace cslam
