#include "system/io/png_fast_decode.h"

#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <unistd.h>

#include <csetjmp>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "system/io/png_codec.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;

constexpr PngPixels kEveryRequest[] = {PngPixels::kGrey8, PngPixels::kGreyAnyDepth,
                                       PngPixels::kUnchanged};

const char* Name(PngPixels pixels) {
  switch (pixels) {
    case PngPixels::kGrey8:
      return "kGrey8";
    case PngPixels::kGreyAnyDepth:
      return "kGreyAnyDepth";
    case PngPixels::kUnchanged:
      return "kUnchanged";
  }
  return "?";
}

// One folder per test: ctest runs the tests of this file side by side.
fs::path Scratch() {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() / ("cslam_png_fast_" + std::string(test->name()) +
                                                    "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string Save(const Bytes& bytes, const std::string& name) {
  const std::string path = (Scratch() / name).string();
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

Bytes Load(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

// What a PNG writer is asked for; `extra` adds chunks (palette, tRNS, gAMA, text) before writing.
struct Layout {
  int width = 1, height = 1;
  int depth = 8;
  int colour = PNG_COLOR_TYPE_GRAY;
  int filters = PNG_FILTER_NONE;  // libpng's mask: one bit forces that filter on every row
  int interlace = PNG_INTERLACE_NONE;
  std::function<void(png_structp, png_infop)> extra;
};

// 8-bit grey of that size, rows filtered as libpng's heuristic picks unless `filters` says.
Layout Grey8(int width, int height, int filters = PNG_ALL_FILTERS) {
  Layout l;
  l.width = width;
  l.height = height;
  l.filters = filters;
  return l;
}

int Channels(int colour) {
  switch (colour) {
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    default:
      return 1;
  }
}

std::size_t RowBytes(const Layout& l) {
  return (static_cast<std::size_t>(l.width) * Channels(l.colour) * l.depth + 7) / 8;
}

// Rows of three kinds in turn so that every filter meets every case: noise, flat runs (the
// ties of Paeth's predictor) and ramps with a little noise.
Bytes Samples(const Layout& l, unsigned seed) {
  std::mt19937 rng(seed);
  const std::size_t row_bytes = RowBytes(l);
  Bytes samples(row_bytes * static_cast<std::size_t>(l.height));
  for (int y = 0; y < l.height; ++y) {
    unsigned char* row = &samples[static_cast<std::size_t>(y) * row_bytes];
    for (std::size_t i = 0; i < row_bytes; ++i) {
      switch (y % 3) {
        case 0:
          row[i] = static_cast<unsigned char>(rng());
          break;
        case 1:
          row[i] = static_cast<unsigned char>(40 * ((i / 5 + static_cast<std::size_t>(y)) % 4));
          break;
        default:
          row[i] = static_cast<unsigned char>(3 * i + 2 * static_cast<std::size_t>(y) + rng() % 5);
      }
    }
  }
  if (l.colour == PNG_COLOR_TYPE_PALETTE)
    for (unsigned char& s : samples) s %= 4;
  return samples;
}

void AppendBytes(png_structp png, png_bytep data, png_size_t size) {
  auto* out = static_cast<Bytes*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}

// libpng itself writes the test files: an encoder independent of the decoder under test.
Bytes WriteWithLibpng(const Layout& l, const Bytes& samples) {
  Bytes out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    ADD_FAILURE() << "libpng could not write the test image";
    return {};
  }
  png_set_write_fn(png, &out, AppendBytes, nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(l.width), static_cast<png_uint_32>(l.height),
               l.depth, l.colour, l.interlace, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, l.filters);
  if (l.extra) l.extra(png, info);
  png_write_info(png, info);
  std::vector<png_bytep> rows(static_cast<std::size_t>(l.height));
  for (int y = 0; y < l.height; ++y)
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(&samples[static_cast<std::size_t>(y) * RowBytes(l)]);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

std::uint32_t Get32(const Bytes& b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) << 24 | static_cast<std::uint32_t>(b[at + 1]) << 16 |
         static_cast<std::uint32_t>(b[at + 2]) << 8 | b[at + 3];
}

void Put32(Bytes* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + static_cast<std::size_t>(i)] = static_cast<unsigned char>(v >> (24 - 8 * i));
}

struct Chunk {
  std::size_t at = 0;  // offset of its length field
  std::uint32_t length = 0;
  std::string name;
  std::size_t data() const { return at + 8; }
};

std::vector<Chunk> Chunks(const Bytes& png) {
  std::vector<Chunk> chunks;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    Chunk c{at, Get32(png, at), std::string(png.begin() + static_cast<long>(at) + 4, png.begin() + static_cast<long>(at) + 8)};
    chunks.push_back(c);
    at += 12 + c.length;
  }
  return chunks;
}

const Chunk& Find(const std::vector<Chunk>& chunks, const std::string& name) {
  for (const Chunk& c : chunks)
    if (c.name == name) return c;
  throw std::runtime_error("no " + name + " chunk");
}

void FixCrc(Bytes* png, const Chunk& c) {
  Put32(png, c.data() + c.length,
        static_cast<std::uint32_t>(crc32(0, png->data() + c.at + 4, c.length + 4)));
}

Bytes MakeChunk(const std::string& name, const Bytes& data) {
  Bytes chunk(12 + data.size());
  Put32(&chunk, 0, static_cast<std::uint32_t>(data.size()));
  std::memcpy(chunk.data() + 4, name.data(), 4);
  std::copy(data.begin(), data.end(), chunk.begin() + 8);
  Put32(&chunk, 8 + data.size(), static_cast<std::uint32_t>(crc32(0, chunk.data() + 4, static_cast<uInt>(data.size() + 4))));
  return chunk;
}

Bytes JoinedIdat(const Bytes& png) {
  Bytes idat;
  for (const Chunk& c : Chunks(png))
    if (c.name == "IDAT") idat.insert(idat.end(), png.begin() + static_cast<long>(c.data()), png.begin() + static_cast<long>(c.data() + c.length));
  return idat;
}

Bytes Inflate(const Bytes& zlib_stream, std::size_t size) {
  Bytes out(size);
  uLongf out_size = size;
  EXPECT_EQ(uncompress(out.data(), &out_size, zlib_stream.data(), zlib_stream.size()), Z_OK);
  EXPECT_EQ(out_size, size);
  return out;
}

// The file `png` with its image data replaced by `filtered` rows (each after its filter byte).
Bytes WithRows(const Bytes& png, const Bytes& filtered) {
  uLongf size = compressBound(filtered.size());
  Bytes stream(size);
  EXPECT_EQ(compress(stream.data(), &size, filtered.data(), filtered.size()), Z_OK);
  stream.resize(size);
  const std::vector<Chunk> chunks = Chunks(png);
  const Chunk& ihdr = Find(chunks, "IHDR");
  Bytes out(png.begin(), png.begin() + static_cast<long>(ihdr.at + 12 + ihdr.length));
  for (const Bytes& chunk : {MakeChunk("IDAT", stream), MakeChunk("IEND", {})})
    out.insert(out.end(), chunk.begin(), chunk.end());
  return out;
}

// PNG's forward filters (spec section 9), every row with filter `type`: files with filters
// libpng does not write (it filters no row of width 1 with Sub, Average or Paeth, nor an image
// of height 1 with Up, Average or Paeth).
Bytes FilterRows(const Bytes& samples, std::size_t row_bytes, std::size_t bpp, int type) {
  const std::size_t height = samples.size() / row_bytes;
  const Bytes zeros(row_bytes, 0);
  Bytes out;
  for (std::size_t y = 0; y < height; ++y) {
    const unsigned char* row = &samples[y * row_bytes];
    const unsigned char* above = y == 0 ? zeros.data() : &samples[(y - 1) * row_bytes];
    out.push_back(static_cast<unsigned char>(type));
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int a = i >= bpp ? row[i - bpp] : 0, b = above[i], c = i >= bpp ? above[i - bpp] : 0;
      int predictor = 0;
      if (type == 1) predictor = a;
      if (type == 2) predictor = b;
      if (type == 3) predictor = (a + b) / 2;
      if (type == 4) {
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        predictor = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
      }
      out.push_back(static_cast<unsigned char>(row[i] - predictor));
    }
  }
  return out;
}

void ExpectSame(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.type(), b.type()) << cv::typeToString(a.type()) << " vs " << cv::typeToString(b.type());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// ReadPng gives what libpng alone gives for the file: the same image, or an error naming it.
void ExpectReadPngAsLibpng(const std::string& path, PngPixels pixels) {
  SCOPED_TRACE(Name(pixels));
  const Bytes bytes = Load(path);
  cv::Mat reference;
  std::string reference_error;
  try {
    reference = DecodePngWithLibpng(bytes, pixels, path);
  } catch (const InputError& e) {
    reference_error = e.what();
  }
  try {
    ExpectSame(ReadPng(path, pixels), reference);
    EXPECT_EQ(reference_error, "") << "libpng alone refuses the file; ReadPng decoded it";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), reference_error);
  }
}

// Checks that the fast path finds `bytes` corrupt, and saves them as `name`.png for ReadPng.
std::string SaveCorrupt(const Bytes& bytes, const std::string& name) {
  PngFastDecoder decoder;
  cv::Mat image;
  EXPECT_EQ(decoder.Decode(bytes, PngPixels::kGrey8, &image), PngFastResult::kCorrupt);
  return Save(bytes, name + ".png");
}

// Every filter on every row (forced in libpng, and again by the test's own forward filter where
// libpng drops it at width or height 1) and libpng's own mix, for grey, RGB and RGBA in 8 and
// 16 bits, at widths and heights of one, odd sizes, and rows of whole and partial 16-byte
// blocks; libpng decodes each file for reference.
TEST(PngFastDecode, EveryFilterLayoutAndSizeDecodesAsLibpngDoes) {
  const int kFilters[] = {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_FILTER_AVG,
                          PNG_FILTER_PAETH, PNG_ALL_FILTERS};
  const int kForced[] = {0, 1, 2, 3, 4, -1};  // the filter-type byte each forces; -1: any
  const int kSizes[][2] = {{1, 1}, {1, 9}, {9, 1}, {37, 23}, {64, 5}, {53, 17}};
  PngFastDecoder decoder;
  unsigned seed = 1;
  int decoded = 0;
  for (const int colour : {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA}) {
    for (const int depth : {8, 16}) {
      for (int f = 0; f < 6; ++f) {
        for (const auto& size : kSizes) {
          Layout l;
          l.width = size[0];
          l.height = size[1];
          l.depth = depth;
          l.colour = colour;
          l.filters = kFilters[f];
          SCOPED_TRACE(::testing::Message() << "colour " << colour << ", depth " << depth << ", filter "
                                            << kForced[f] << ", " << l.width << "x" << l.height);
          const Bytes samples = Samples(l, seed++);
          const Bytes png = WriteWithLibpng(l, samples);
          ASSERT_FALSE(png.empty());
          const std::size_t stride = RowBytes(l) + 1;
          const Bytes filtered = Inflate(JoinedIdat(png), stride * static_cast<std::size_t>(l.height));
          const bool libpng_drops = (l.width == 1 && (kForced[f] == 1 || kForced[f] >= 3)) ||
                                    (l.height == 1 && kForced[f] >= 2);
          for (int y = 0; y < l.height && kForced[f] >= 0; ++y)
            ASSERT_EQ(filtered[static_cast<std::size_t>(y) * stride], libpng_drops ? 0 : kForced[f]) << "row " << y;
          std::vector<Bytes> files = {png};
          if (kForced[f] >= 0) {
            const std::size_t bpp = RowBytes(l) / static_cast<std::size_t>(l.width);
            files.push_back(WithRows(png, FilterRows(samples, RowBytes(l), bpp, kForced[f])));
          }
          for (const Bytes& file : files) {
            for (const PngPixels pixels : kEveryRequest) {
              SCOPED_TRACE(::testing::Message() << Name(pixels) << (&file == &files[0] ? ", libpng's filtering" : ", filtered by hand"));
              const cv::Mat reference = DecodePngWithLibpng(file, pixels, "test.png");
              cv::Mat image;
              const PngFastResult result = decoder.Decode(file, pixels, &image);
              if (colour != PNG_COLOR_TYPE_GRAY && pixels != PngPixels::kUnchanged) {
                EXPECT_EQ(result, PngFastResult::kUnsupported) << "colour to grey is libpng's";
                continue;
              }
              ASSERT_EQ(result, PngFastResult::kDecoded);
              ExpectSame(image, reference);
              ++decoded;
            }
          }
        }
      }
    }
  }
  // Per layout and size: libpng's file, and for the five forced filters the hand-filtered one.
  EXPECT_EQ(decoded, (6 + 5) * 6 * (2 * 3 + 2 * 2 * 1));
}

// The layouts and chunks the fast path leaves to libpng: ReadPng still gives libpng's pixels.
TEST(PngFastDecode, LeavesOtherLayoutsAndPixelChangingChunksToLibpng) {
  png_color palette[4] = {{0, 0, 0}, {255, 0, 0}, {10, 200, 30}, {90, 90, 250}};
  png_color_16 grey_key{};
  grey_key.gray = 40;
  png_color_16 rgb_key{};
  rgb_key.red = rgb_key.green = rgb_key.blue = 40;
  png_byte alpha[4] = {255, 0, 128, 255};
  struct Case {
    const char* name;
    Layout layout;
  };
  std::vector<Case> cases;
  auto add = [&](const char* name, int depth, int colour, int interlace,
                 std::function<void(png_structp, png_infop)> extra = {}) {
    Layout l = Grey8(29, 17);
    l.depth = depth;
    l.colour = colour;
    l.interlace = interlace;
    l.extra = std::move(extra);
    cases.push_back({name, l});
  };
  add("interlaced grey", 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_ADAM7);
  add("interlaced RGB", 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_ADAM7);
  add("palette", 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE,
      [&](png_structp p, png_infop i) { png_set_PLTE(p, i, palette, 4); });
  add("palette with alpha", 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE, [&](png_structp p, png_infop i) {
    png_set_PLTE(p, i, palette, 4);
    png_set_tRNS(p, i, alpha, 4, nullptr);
  });
  add("1-bit grey", 1, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE);
  add("4-bit grey", 4, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE);
  add("grey and alpha", 8, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE);
  add("grey with tRNS", 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
      [&](png_structp p, png_infop i) { png_set_tRNS(p, i, nullptr, 0, &grey_key); });
  add("RGB with tRNS", 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
      [&](png_structp p, png_infop i) { png_set_tRNS(p, i, nullptr, 0, &rgb_key); });
  add("grey with gAMA", 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
      [](png_structp p, png_infop i) { png_set_gAMA(p, i, 0.7); });
  add("RGB with sRGB", 16, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
      [](png_structp p, png_infop i) { png_set_sRGB(p, i, PNG_sRGB_INTENT_PERCEPTUAL); });
  PngFastDecoder decoder;
  unsigned seed = 100;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Bytes png = WriteWithLibpng(c.layout, Samples(c.layout, seed++));
    ASSERT_FALSE(png.empty());
    const std::string path = Save(png, "other.png");
    for (const PngPixels pixels : kEveryRequest) {
      cv::Mat image;
      EXPECT_EQ(decoder.Decode(png, pixels, &image), PngFastResult::kUnsupported) << Name(pixels);
      ExpectReadPngAsLibpng(path, pixels);
      EXPECT_FALSE(ReadPng(path, pixels).empty());
    }
  }
  fs::remove_all(Scratch());
}

// Text, time and pixel-size chunks change no pixel: the fast path reads past them.
TEST(PngFastDecode, DecodesPastMetadataChunks) {
  Layout l = Grey8(31, 7);
  png_text text[2] = {};
  text[0].compression = PNG_TEXT_COMPRESSION_NONE;
  text[0].key = const_cast<png_charp>("Comment");
  text[0].text = const_cast<png_charp>("a test image");
  text[1].compression = PNG_TEXT_COMPRESSION_zTXt;
  text[1].key = const_cast<png_charp>("Description");
  text[1].text = const_cast<png_charp>("written with libpng by png_fast_decode_test");
  l.extra = [&](png_structp p, png_infop i) {
    png_set_text(p, i, text, 2);
    png_set_pHYs(p, i, 2835, 2835, PNG_RESOLUTION_METER);
  };
  const Bytes png = WriteWithLibpng(l, Samples(l, 7));
  const std::vector<Chunk> chunks = Chunks(png);
  for (const char* name : {"tEXt", "zTXt", "pHYs"}) EXPECT_NO_THROW(Find(chunks, name)) << name;
  PngFastDecoder decoder;
  cv::Mat image;
  ASSERT_EQ(decoder.Decode(png, PngPixels::kGrey8, &image), PngFastResult::kDecoded);
  ExpectSame(image, DecodePngWithLibpng(png, PngPixels::kGrey8, "test.png"));
}

// A damaged file is never decoded into garbage: the fast path finds it corrupt and ReadPng
// throws an InputError naming the file, as libpng alone does.
TEST(PngFastDecode, DamagedFilesAreInputErrorsNamingTheFile) {
  Layout l = Grey8(61, 33);
  const Bytes good = WriteWithLibpng(l, Samples(l, 3));
  const std::vector<Chunk> chunks = Chunks(good);
  const Chunk& ihdr = Find(chunks, "IHDR");
  const Chunk& idat = Find(chunks, "IDAT");
  ASSERT_GT(idat.length, 40u);
  std::vector<std::pair<std::string, Bytes>> damaged;
  {
    Bytes b = good;  // a flipped byte in the image data, the CRC left as it was
    b[idat.data() + idat.length / 2] ^= 0x10;
    damaged.emplace_back("idat_crc", b);
    FixCrc(&b, idat);  // the same, CRC made to match: the zlib stream itself is wrong
    damaged.emplace_back("idat_data", b);
  }
  {
    Bytes b = good;  // the Adler-32 at the end of the zlib stream, the CRC made to match
    const Chunk& last = chunks[chunks.size() - 2];
    ASSERT_EQ(last.name, "IDAT");
    b[last.data() + last.length - 1] ^= 0x01;
    FixCrc(&b, last);
    damaged.emplace_back("adler", b);
  }
  {
    Bytes b = good;  // the header's CRC
    b[ihdr.data() + ihdr.length] ^= 0x01;
    damaged.emplace_back("ihdr_crc", b);
  }
  for (const std::size_t keep : {good.size() / 2, good.size() - 12, std::size_t{40}}) {
    damaged.emplace_back("cut_" + std::to_string(keep), Bytes(good.begin(), good.begin() + static_cast<long>(keep)));
  }
  {
    Bytes b = good;  // one row more than the data holds
    Put32(&b, ihdr.data() + 4, static_cast<std::uint32_t>(l.height + 1));
    FixCrc(&b, ihdr);
    damaged.emplace_back("short_data", b);
  }
  {
    const std::size_t stride = RowBytes(l) + 1;  // a filter type PNG does not define
    Bytes filtered = Inflate(JoinedIdat(good), stride * static_cast<std::size_t>(l.height));
    filtered[5 * stride] = 5;
    damaged.emplace_back("filter_5", WithRows(good, filtered));
  }
  for (const auto& [name, bytes] : damaged) {
    SCOPED_TRACE(name);
    const std::string path = SaveCorrupt(bytes, name);
    for (const PngPixels pixels : kEveryRequest) {
      try {
        ReadPng(path, pixels);
        ADD_FAILURE() << path << " was decoded (" << Name(pixels) << ")";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      }
    }
  }
  fs::remove_all(Scratch());
}

// Damage libpng tolerates (trailing image data, a bad CRC on an ancillary chunk) stops the fast
// path all the same; libpng then decides, as it did before there was a fast path.
TEST(PngFastDecode, DamageLibpngToleratesGivesWhatLibpngGives) {
  Layout l = Grey8(40, 12);
  l.extra = [](png_structp p, png_infop i) { png_set_pHYs(p, i, 2835, 2835, PNG_RESOLUTION_METER); };
  const Bytes good = WriteWithLibpng(l, Samples(l, 5));
  const std::vector<Chunk> chunks = Chunks(good);
  std::vector<std::pair<std::string, Bytes>> damaged;
  {
    Bytes b = good;  // one row fewer than the data holds
    Put32(&b, Find(chunks, "IHDR").data() + 4, static_cast<std::uint32_t>(l.height - 1));
    FixCrc(&b, Find(chunks, "IHDR"));
    damaged.emplace_back("long_data", b);
  }
  {
    Bytes b = good;
    b[Find(chunks, "pHYs").data()] ^= 0x01;
    damaged.emplace_back("phys_crc", b);
  }
  for (const auto& [name, bytes] : damaged) {
    SCOPED_TRACE(name);
    const std::string path = SaveCorrupt(bytes, name);
    for (const PngPixels pixels : kEveryRequest) ExpectReadPngAsLibpng(path, pixels);
  }
  fs::remove_all(Scratch());
}

// The images the fast path exists for: a KITTI raw 0005 frame, split in many IDAT chunks.
TEST(PngFastDecode, KittiFrameDecodesAsLibpngDoes) {
  const fs::path path = testing::RawDriveDir() / "image_01" / "data" / "0000000077.png";
  ASSERT_TRUE(fs::exists(path)) << path << " not found (set CSLAM_SHARED_DATA)";
  const Bytes png = Load(path);
  int idat_chunks = 0;
  for (const Chunk& c : Chunks(png)) idat_chunks += c.name == "IDAT";
  EXPECT_GT(idat_chunks, 1);
  PngFastDecoder decoder;
  for (const PngPixels pixels : kEveryRequest) {
    SCOPED_TRACE(Name(pixels));
    cv::Mat image;
    ASSERT_EQ(decoder.Decode(png, pixels, &image), PngFastResult::kDecoded);
    const cv::Mat reference = DecodePngWithLibpng(png, pixels, path.string());
    ASSERT_EQ(reference.size(), cv::Size(1242, 375));
    ExpectSame(image, reference);
    ExpectSame(ReadPng(path.string(), pixels), reference);
  }
  // The decoder keeps its buffers: a second, smaller image after a large one decodes right.
  Layout l = Grey8(5, 3, PNG_FILTER_PAETH);
  const Bytes small = WriteWithLibpng(l, Samples(l, 11));
  cv::Mat image;
  ASSERT_EQ(decoder.Decode(small, PngPixels::kGrey8, &image), PngFastResult::kDecoded);
  ExpectSame(image, DecodePngWithLibpng(small, PngPixels::kGrey8, "small.png"));
}

}  // namespace
}  // namespace cslam
