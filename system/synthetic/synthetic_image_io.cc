#include "system/synthetic/synthetic_image_io.h"

#include <charconv>
#include <cstdio>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/io/image_io.h"
#include "system/io/png_codec.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSequenceSubdir = "sequences/00";
constexpr const char* kPosesFile = "poses/00.txt";

}  // namespace

std::string SyntheticPosesFile(const std::string& dir) {
  return (fs::path(dir) / kPosesFile).string();
}

std::string SyntheticFrameFile(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return name;
}

std::string SyntheticImagesDir(const std::string& dir) {
  return (fs::path(dir) / kSequenceSubdir).string();
}

bool HasSyntheticImages(const std::string& dir) {
  std::error_code ec;
  const fs::path seq = SyntheticImagesDir(dir);
  return fs::is_directory(seq / "image_0", ec) && fs::is_regular_file(seq / "calib.txt", ec);
}

cv::Mat ReadObjectIdImage(const std::string& dir, int frame) {
  const std::string path = (fs::path(SyntheticImagesDir(dir)) / "object_id" / SyntheticFrameFile(frame)).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path, "expected an object-id image; it does not exist");
  cv::Mat ids = ReadPng(path, PngPixels::kUnchanged);
  if (ids.type() != CV_16UC1)
    throw InputError(path, "expected a 16-bit single-channel object-id PNG");
  return ids;
}

}  // namespace cslam
