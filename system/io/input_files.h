#pragma once
// File-level helpers shared by the readers: opening text files, image lists, image decoding
// and timestamp files. Every failure throws InputError naming the file (and line).
#include <opencv2/core/mat.hpp>

#include <fstream>
#include <string>
#include <vector>

namespace cslam {

/// Opens a text input file. Throws InputError("cannot open the <what> (missing or
/// unreadable)") when `path` is not a readable regular file (a folder in its place included).
std::ifstream OpenTextFile(const std::string& path, const std::string& what);

/// The whitespace-separated numbers of `text` (from `path`, line `line`). Throws
/// InputError(path, line, "<label> field N: expected a finite number, got 'x'") on a token that
/// is not a finite number.
std::vector<double> ParseNumbers(const std::string& text, const std::string& path, int line,
                                 const std::string& label = "");

/// Sorted paths of the `*.png` files in `dir`. Throws InputError when `dir` is missing, not a
/// folder or holds no PNG.
std::vector<std::string> ListPngFiles(const std::string& dir);

/// Decodes `path` as 8-bit grey (colour images are converted). Throws InputError when the
/// file is missing, cannot be decoded, or (when expected_width > 0) has another size.
cv::Mat LoadGreyImage(const std::string& path, int expected_width = 0, int expected_height = 0);

/// KITTI raw timestamps ("YYYY-MM-DD HH:MM:SS.nnnnnnnnn" per line) as seconds from the first
/// line. Throws InputError (file:line) on a malformed line or a non-increasing time.
std::vector<double> ReadKittiRawTimestamps(const std::string& path);

/// One number of seconds per line (KITTI odometry times.txt), shifted to start at 0. Throws
/// InputError (file:line) on a malformed or non-finite value or a non-increasing time.
std::vector<double> ReadSecondsTimestamps(const std::string& path);

}  // namespace cslam
