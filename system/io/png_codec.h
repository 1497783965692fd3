#pragma once
// PNG decoding and encoding with libpng itself rather than OpenCV's imgcodecs: imgcodecs links
// GDAL and some 140 shared libraries whose loading and symbol binding cost every process a
// large part of a short run's wall time, for a format cslam reads and writes only as PNG.
// Decoding asks libpng for the transformations imread asks for (16 → 8 bits, alpha stripped,
// palette and low bit depths expanded, RGB → grey with weights 0.299 / 0.587), so the pixels
// are those imread gives. The common layouts (8-bit grey above all) take a faster path with
// the same pixels (png_fast_decode.h); libpng decodes the rest and reports every damaged file.
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

namespace cslam {

/// What a decoded PNG becomes.
enum class PngPixels {
  kGrey8,        ///< CV_8UC1 whatever the file holds (imread's IMREAD_GRAYSCALE)
  kGreyAnyDepth, ///< CV_8UC1 or CV_16UC1 by the file's depth (IMREAD_GRAYSCALE | ANYDEPTH)
  kUnchanged,    ///< the file's depth and channels, colour as BGR / BGRA (IMREAD_UNCHANGED)
};

/// Decodes the PNG file at `path`. Throws InputError naming the file when it cannot be opened,
/// is not a PNG, or libpng reports it corrupt (with libpng's message).
cv::Mat ReadPng(const std::string& path, PngPixels pixels);

/// Decodes the PNG file contents `bytes` with libpng alone, as ReadPng does the files its
/// fast path leaves: the reference that path is held to, for tests and benchmarks. Throws
/// InputError naming `name` when `bytes` is not a PNG or libpng reports it corrupt.
cv::Mat DecodePngWithLibpng(std::span<const unsigned char> bytes, PngPixels pixels,
                            const std::string& name);

/// Encodes `image` (CV_8U or CV_16U with 1, 3 (BGR) or 4 (BGRA) channels) as PNG. Throws
/// std::invalid_argument for an empty image or another type.
std::vector<unsigned char> EncodePng(const cv::Mat& image);

}  // namespace cslam
