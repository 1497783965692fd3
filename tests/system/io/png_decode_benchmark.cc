// Decoding one KITTI raw 0005 frame (1242×375, 8-bit grey, Sub-filtered rows in 35 IDAT
// chunks) from memory, as the dataset reader asks for it (PngPixels::kGreyAnyDepth): libpng
// with zlib against the fast path (libdeflate and cslam's own unfiltering), and ReadPng from
// the file as the reader calls it. CPU time per image is the figure to compare: the reader
// thread shares two cores with the frontend.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "system/io/png_codec.h"
#include "system/io/png_fast_decode.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

std::string FramePath() {
  return (testing::RawDriveDir() / "image_00" / "data" / "0000000000.png").string();
}

std::vector<unsigned char> FrameBytes() {
  std::ifstream in(FramePath(), std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

void BM_PngDecodeLibpng(benchmark::State& state) {
  const std::vector<unsigned char> png = FrameBytes();
  if (png.empty()) return state.SkipWithError("KITTI drive 0005 images not found (set CSLAM_SHARED_DATA)");
  for (auto _ : state) benchmark::DoNotOptimize(DecodePngWithLibpng(png, PngPixels::kGreyAnyDepth, "frame"));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * 1242 * 375);
}
BENCHMARK(BM_PngDecodeLibpng)->Unit(benchmark::kMicrosecond);

void BM_PngDecodeFast(benchmark::State& state) {
  const std::vector<unsigned char> png = FrameBytes();
  if (png.empty()) return state.SkipWithError("KITTI drive 0005 images not found (set CSLAM_SHARED_DATA)");
  PngFastDecoder decoder;
  cv::Mat image;
  for (auto _ : state) {
    if (decoder.Decode(png, PngPixels::kGreyAnyDepth, &image) != PngFastResult::kDecoded)
      return state.SkipWithError("the fast path did not decode the frame");
    benchmark::DoNotOptimize(image.data);
    image.release();  // as the reader's: a new image per frame
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * 1242 * 375);
}
BENCHMARK(BM_PngDecodeFast)->Unit(benchmark::kMicrosecond);

void BM_ReadPngFromFile(benchmark::State& state) {
  if (!std::filesystem::exists(FramePath()))
    return state.SkipWithError("KITTI drive 0005 images not found (set CSLAM_SHARED_DATA)");
  for (auto _ : state) benchmark::DoNotOptimize(ReadPng(FramePath(), PngPixels::kGreyAnyDepth));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * 1242 * 375);
}
BENCHMARK(BM_ReadPngFromFile)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cslam
