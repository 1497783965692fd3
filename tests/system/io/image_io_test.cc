#include "system/io/image_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

TEST(ImageIo, WritesALosslessPngAtomically) {
  const fs::path dir = fs::temp_directory_path() / "cslam_png_test";
  fs::remove_all(dir);
  cv::Mat image(30, 40, CV_8UC3);
  cv::randu(image, 0, 255);
  const std::string path = (dir / "render" / "a.png").string();
  WritePng(image, path);
  EXPECT_FALSE(fs::exists(TemporaryPathFor(path)));
  const cv::Mat back = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  fs::remove_all(dir);
}

TEST(ImageIo, FrameImageNamesArePaddedToSixDigits) {
  EXPECT_EQ(FrameImageName("snapshot", 42), "snapshot_000042.png");
  EXPECT_EQ(FrameImageName("overlay", 0), "overlay_000000.png");
  EXPECT_EQ(FrameImageName("overlay", 1234567), "overlay_1234567.png");
}

TEST(ImageIo, EmptyImageOrUnwritablePathIsAnOutputError) {
  EXPECT_THROW(WritePng(cv::Mat(), "/tmp/cslam_never.png"), OutputError);
  const fs::path blocker = fs::temp_directory_path() / "cslam_png_blocker";
  { std::ofstream(blocker) << "x"; }
  EXPECT_THROW(WritePng(cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)), (blocker / "x.png").string()),
               OutputError);
  fs::remove(blocker);
}

}  // namespace
}  // namespace cslam
