#include "system/io/png_codec.h"

#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

// One folder per test: ctest runs the tests of this file side by side.
fs::path Scratch() {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() /
                       ("cslam_png_codec_" + std::string(test->name()) + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

cv::Mat Random(int type, int seed) {
  cv::Mat image(37, 53, type);
  cv::theRNG().state = static_cast<uint64_t>(seed);
  cv::randu(image, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

void ExpectSame(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.type(), b.type()) << cv::typeToString(a.type()) << " vs " << cv::typeToString(b.type());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// Whatever OpenCV writes (grey, BGR, BGRA; 8 and 16 bits; 1-bit grey), cslam reads as imread
// does for the same request: same type, same pixels, including colour → grey.
TEST(PngCodec, DecodesEveryLayoutOpenCvWritesAsImreadDoes) {
  const fs::path dir = Scratch();
  int seed = 1;
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    const std::string path = (dir / ("t" + std::to_string(type) + ".png")).string();
    ASSERT_TRUE(cv::imwrite(path, Random(type, seed++)));
    SCOPED_TRACE(cv::typeToString(type));
    ExpectSame(ReadPng(path, PngPixels::kGrey8), cv::imread(path, cv::IMREAD_GRAYSCALE));
    ExpectSame(ReadPng(path, PngPixels::kGreyAnyDepth),
               cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH));
    ExpectSame(ReadPng(path, PngPixels::kUnchanged), cv::imread(path, cv::IMREAD_UNCHANGED));
  }
  const std::string bilevel = (dir / "bilevel.png").string();
  cv::Mat bits = Random(CV_8UC1, 9) > 128;
  ASSERT_TRUE(cv::imwrite(bilevel, bits, {cv::IMWRITE_PNG_BILEVEL, 1}));
  ExpectSame(ReadPng(bilevel, PngPixels::kGrey8), cv::imread(bilevel, cv::IMREAD_GRAYSCALE));
  fs::remove_all(dir);
}

// A palette image written interlaced by libpng itself: two layouts OpenCV never writes.
TEST(PngCodec, DecodesAnInterlacedPaletteImageAsImreadDoes) {
  const std::string path = (Scratch() / "palette.png").string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  const int w = 29, h = 17;
  png_set_IHDR(png, info, w, h, 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_ADAM7,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_color palette[4] = {{0, 0, 0}, {255, 0, 0}, {10, 200, 30}, {90, 90, 250}};
  png_set_PLTE(png, info, palette, 4);
  png_write_info(png, info);
  std::vector<unsigned char> pixels(w * h);
  for (int i = 0; i < w * h; ++i) pixels[i] = static_cast<unsigned char>((i * 7 + i / w) % 4);
  std::vector<png_bytep> rows(h);
  for (int y = 0; y < h; ++y) rows[y] = pixels.data() + y * w;
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
  ExpectSame(ReadPng(path, PngPixels::kGrey8), cv::imread(path, cv::IMREAD_GRAYSCALE));
  ExpectSame(ReadPng(path, PngPixels::kUnchanged), cv::imread(path, cv::IMREAD_UNCHANGED));
  fs::remove_all(Scratch());
}

TEST(PngCodec, EncodedImagesDecodeToTheSamePixelsWithOpenCvAndCslam) {
  int seed = 20;
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3}) {
    SCOPED_TRACE(cv::typeToString(type));
    const cv::Mat image = Random(type, seed++);
    const std::vector<unsigned char> bytes = EncodePng(image);
    ExpectSame(cv::imdecode(bytes, cv::IMREAD_UNCHANGED), image);
    const std::string path = (Scratch() / "round.png").string();
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    ExpectSame(ReadPng(path, PngPixels::kUnchanged), image);
  }
  EXPECT_THROW(EncodePng(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(EncodePng(cv::Mat(4, 4, CV_32FC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(EncodePng(cv::Mat(4, 4, CV_8UC2, cv::Scalar(0))), std::invalid_argument);
  fs::remove_all(Scratch());
}

TEST(PngCodec, ATruncatedOrForeignFileIsAnInputErrorNamingIt) {
  const fs::path dir = Scratch();
  const std::string good = (dir / "good.png").string();
  ASSERT_TRUE(cv::imwrite(good, Random(CV_8UC1, 3)));
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string cut = (dir / "cut.png").string();
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const std::string text = (dir / "text.png").string();
  std::ofstream(text) << "not an image\n";
  for (const std::string& path : {cut, text, (dir / "missing.png").string()}) {
    try {
      ReadPng(path, PngPixels::kGrey8);
      ADD_FAILURE() << path << " was decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

// ReadPng keeps its file buffer between calls; a larger file grows (moves) it, and the bytes
// decoded must be the new buffer's (a span taken before the read pointed at freed memory:
// found by the png fuzzer under clang, whose argument order differs from gcc's).
TEST(PngCodec, ALargerFileAfterASmallerOneDecodesItsOwnPixels) {
  const fs::path dir = Scratch();
  cv::Mat big(400, 600, CV_8UC1);
  cv::theRNG().state = 11;
  cv::randu(big, 0, 256);  // incompressible: the file is larger than the buffer's first block
  const cv::Mat small = Random(CV_8UC1, 5);
  const std::string small_path = (dir / "small.png").string(), big_path = (dir / "big.png").string();
  ASSERT_TRUE(cv::imwrite(small_path, small));
  ASSERT_TRUE(cv::imwrite(big_path, big));
  ASSERT_GT(fs::file_size(big_path), 1u << 17);
  for (const std::string& path : {small_path, big_path, small_path, big_path})
    ExpectSame(ReadPng(path, PngPixels::kGrey8), cv::imread(path, cv::IMREAD_GRAYSCALE));
  fs::remove_all(dir);
}

// The image is allocated before its data is read, so a header that claims more pixels than
// the file's compressed data could ever hold is refused first (60 000 × 60 000 in 70 bytes).
TEST(PngCodec, AHeaderClaimingMorePixelsThanItsDataCanHoldIsAnInputErrorNamingTheFile) {
  auto chunk = [](const std::string& type, const std::string& data) {
    std::string out;
    for (int shift : {24, 16, 8, 0}) out += static_cast<char>((data.size() >> shift) & 0xff);
    const std::string body = type + data;
    out += body;
    const uLong crc = crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()));
    for (int shift : {24, 16, 8, 0}) out += static_cast<char>((crc >> shift) & 0xff);
    return out;
  };
  const std::string size = std::string("\x00\x00\xea\x60", 4);  // 60 000
  const std::string ihdr = size + size + std::string("\x08\x00\x00\x00\x00", 5);
  const std::string idat = std::string("\x78\x9c\x63\x60\x00\x00\x00\x02\x00\x01", 10);
  const std::string file = std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
                           chunk("IDAT", idat) + chunk("IEND", "");
  const fs::path dir = Scratch();
  const std::string path = (dir / "huge_header.png").string();
  std::ofstream(path, std::ios::binary) << file;
  for (PngPixels pixels : {PngPixels::kGrey8, PngPixels::kUnchanged}) {
    try {
      ReadPng(path, pixels);
      ADD_FAILURE() << "decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("more pixels than"), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

// libpng allocates a chunk's claimed length before reading it: a 49-byte file whose text chunk
// claims 2 GB (as the png fuzzer's reproducer does) is refused by its chunk lengths first.
TEST(PngCodec, AChunkClaimingMoreBytesThanTheFileHoldsIsAnInputErrorNamingIt) {
  const fs::path dir = Scratch();
  const std::string path = (dir / "long_text.png").string();
  static constexpr char kBytes[] =
      "\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR\x00\x00\x00\x02\x00\x00\x00\x02"
      "\x10\x06\x00\x00\x00\x22\x26\xd1\x67\x7a\x00\x00\x03tEXtk\x00vK\x04\xf3\x90\x82";
  const std::string file(kBytes, sizeof(kBytes) - 1);  // the literal's own length, NULs included
  std::ofstream(path, std::ios::binary) << file;
  try {
    ReadPng(path, PngPixels::kUnchanged);
    ADD_FAILURE() << "decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("past the end of the file"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cslam
