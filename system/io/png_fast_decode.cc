#include "system/io/png_fast_decode.h"

#include <libdeflate.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cslam {

namespace {

constexpr unsigned char kSignature[8] = {137, 80, 78, 71, 13, 10, 26, 10};

constexpr std::uint32_t ChunkName(const char (&name)[5]) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(name[0])) << 24 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[1])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[2])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[3]));
}

// libpng's default limits on width and height (PNG_USER_WIDTH_MAX, PNG_USER_HEIGHT_MAX):
// larger images are libpng's to refuse.
constexpr std::uint32_t kMaxDimension = 1000000;
// A chunk length above 2^31 - 1 is invalid (PNG spec 5.3).
constexpr std::uint32_t kMaxChunkLength = 0x7fffffffu;

// Chunks libpng reads without ever changing the pixels it returns: text, time, pixel size.
// Any other ancillary chunk (tRNS, gAMA, sRGB, iCCP, sBIT, bKGD, ...) sends the file to libpng,
// whichever request it answers, rather than this decoder knowing which requests it affects.
bool IsMetadata(std::uint32_t name) {
  return name == ChunkName("tEXt") || name == ChunkName("zTXt") || name == ChunkName("iTXt") ||
         name == ChunkName("tIME") || name == ChunkName("pHYs");
}

std::uint8_t Paeth(int a, int b, int c) {
  // p = a + b - c; the predictor is whichever of a, b, c lies nearest p, ties in that order.
  // Written as selects, not branches: which one wins is data-dependent and unpredictable.
  const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
  const int b_or_c = pb <= pc ? b : c;
  return static_cast<std::uint8_t>(pa <= pb && pa <= pc ? a : b_or_c);
}

#if defined(__SSE2__)
// Sub with one byte per pixel is a running sum of the row mod 256; sixteen bytes at a time as
// a prefix sum in four shifted adds, plus the previous block's last byte. Returns how many
// bytes it did (whole blocks only). `out` may be `in`: each block is loaded before it is stored.
std::size_t UndoSubOneByteSse2(const unsigned char* in, unsigned char* out, std::size_t n) {
  __m128i carry = _mm_setzero_si128();
  std::size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 1));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 2));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 4));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 8));
    x = _mm_add_epi8(x, carry);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), x);
    // Byte 15 into every lane: bytes 8..15 doubled, word 7 into words 4..7, high half to both.
    carry = _mm_shufflehi_epi16(_mm_unpackhi_epi8(x, x), 0xFF);
    carry = _mm_unpackhi_epi64(carry, carry);
  }
  return i;
}
#endif

void UndoSub(const unsigned char* in, unsigned char* out, std::size_t n, std::size_t bpp) {
  std::size_t i = 0;
#if defined(__SSE2__)
  if (bpp == 1) i = UndoSubOneByteSse2(in, out, n);
#endif
  for (; i < bpp; ++i) out[i] = in[i];
  for (; i < n; ++i) out[i] = static_cast<unsigned char>(in[i] + out[i - bpp]);
}

void UndoUp(const unsigned char* in, const unsigned char* prior, unsigned char* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<unsigned char>(in[i] + prior[i]);
}

void UndoAverage(const unsigned char* in, const unsigned char* prior, unsigned char* out,
                 std::size_t n, std::size_t bpp) {
  for (std::size_t i = 0; i < bpp; ++i) out[i] = static_cast<unsigned char>(in[i] + (prior[i] >> 1));
  for (std::size_t i = bpp; i < n; ++i)
    out[i] = static_cast<unsigned char>(in[i] + ((out[i - bpp] + prior[i]) >> 1));
}

void UndoPaeth(const unsigned char* in, const unsigned char* prior, unsigned char* out,
               std::size_t n, std::size_t bpp) {
  // Left of the row a = c = 0, so the predictor is b.
  for (std::size_t i = 0; i < bpp; ++i) out[i] = static_cast<unsigned char>(in[i] + prior[i]);
  for (std::size_t i = bpp; i < n; ++i)
    out[i] = static_cast<unsigned char>(in[i] + Paeth(out[i - bpp], prior[i], prior[i - bpp]));
}

// Undoes one row's filter (PNG spec, section 9): `prior` is the row above, already unfiltered
// (zeros above the first row); `bpp` bytes per whole pixel, at least 1; `out` may be `in`.
// False for a filter type PNG does not define.
bool Unfilter(int filter, const unsigned char* in, const unsigned char* prior, unsigned char* out,
              std::size_t n, std::size_t bpp) {
  switch (filter) {
    case 0:
      if (out != in) std::memcpy(out, in, n);
      return true;
    case 1:
      UndoSub(in, out, n, bpp);
      return true;
    case 2:
      UndoUp(in, prior, out, n);
      return true;
    case 3:
      UndoAverage(in, prior, out, n, bpp);
      return true;
    case 4:
      UndoPaeth(in, prior, out, n, bpp);
      return true;
    default:
      return false;
  }
}

std::uint16_t Sample16(const unsigned char* big_endian) {
  return static_cast<std::uint16_t>(big_endian[0] << 8 | big_endian[1]);
}

// The file's samples, in place, as libpng leaves them for ReadPng: 16-bit samples in the
// machine's order, colour as BGR / BGRA.
void ToOpenCvOrder(cv::Mat* image) {
  const int channels = image->channels();
  const bool sixteen = image->depth() == CV_16U;
  const std::size_t samples = static_cast<std::size_t>(image->cols) * static_cast<std::size_t>(channels);
  for (int y = 0; y < image->rows; ++y) {
    unsigned char* row = image->ptr(y);
    if (!sixteen) {
      for (std::size_t i = 0; i < samples; i += static_cast<std::size_t>(channels)) std::swap(row[i], row[i + 2]);
      continue;
    }
    auto* out = reinterpret_cast<std::uint16_t*>(row);
    for (std::size_t i = 0; i < samples; i += static_cast<std::size_t>(channels)) {
      const unsigned char* p = row + 2 * i;
      std::uint16_t v[4] = {Sample16(p), 0, 0, 0};
      for (int c = 1; c < channels; ++c) v[c] = Sample16(p + 2 * c);
      if (channels >= 3) std::swap(v[0], v[2]);
      for (int c = 0; c < channels; ++c) out[i + static_cast<std::size_t>(c)] = v[c];
    }
  }
}

struct Header {
  std::uint32_t width = 0, height = 0;
  int depth = 0, colour = 0, channels = 0;
};

// The IHDR fields, when the layout and the request are ones this decoder handles.
PngFastResult ReadHeader(const unsigned char* data, PngPixels pixels, Header* header) {
  header->width = PngBigEndian32(data);
  header->height = PngBigEndian32(data + 4);
  header->depth = data[8];
  header->colour = data[9];
  const int compression = data[10], filter = data[11], interlace = data[12];
  if (header->width == 0 || header->height == 0 || compression != 0 || filter != 0 || interlace > 1)
    return PngFastResult::kCorrupt;
  if (header->width > kMaxDimension || header->height > kMaxDimension || interlace != 0 ||
      (header->depth != 8 && header->depth != 16))
    return PngFastResult::kUnsupported;
  switch (header->colour) {
    case 0:
      header->channels = 1;
      return PngFastResult::kDecoded;
    case 2:
    case 6:
      // Colour to grey is libpng's fixed-point weighting, left to it.
      header->channels = header->colour == 2 ? 3 : 4;
      return pixels == PngPixels::kUnchanged ? PngFastResult::kDecoded : PngFastResult::kUnsupported;
    default:
      return PngFastResult::kUnsupported;
  }
}

}  // namespace

std::uint32_t PngBigEndian32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 |
         static_cast<std::uint32_t>(p[2]) << 8 | static_cast<std::uint32_t>(p[3]);
}

PngFastDecoder::PngFastDecoder() : inflater_(libdeflate_alloc_decompressor()) {
  if (!inflater_) throw std::bad_alloc();
}

PngFastDecoder::~PngFastDecoder() { libdeflate_free_decompressor(inflater_); }

PngFastResult PngFastDecoder::Decode(std::span<const unsigned char> bytes, PngPixels pixels,
                                     cv::Mat* image) {
  if (bytes.size() < sizeof(kSignature) || std::memcmp(bytes.data(), kSignature, sizeof(kSignature)) != 0)
    return PngFastResult::kCorrupt;
  // The chunks: IHDR first, the IDATs one after another, IEND; every CRC checked.
  Header header;
  bool have_header = false;
  std::span<const unsigned char> stream;  // the zlib stream: one IDAT's data, or idat_
  int idat_chunks = 0;
  bool idat_ended = false;
  idat_.clear();
  for (std::size_t at = sizeof(kSignature);;) {
    if (bytes.size() - at < 12) return PngFastResult::kCorrupt;  // no IEND
    const std::uint32_t length = PngBigEndian32(&bytes[at]);
    if (length > kMaxChunkLength || length > bytes.size() - at - 12) return PngFastResult::kCorrupt;
    const unsigned char* name_and_data = &bytes[at + 4];
    const unsigned char* data = name_and_data + 4;
    if (libdeflate_crc32(0, name_and_data, length + 4) != PngBigEndian32(data + length))
      return PngFastResult::kCorrupt;
    at += 12 + std::size_t{length};
    const std::uint32_t name = PngBigEndian32(name_and_data);
    if (!have_header) {
      if (name != ChunkName("IHDR") || length != 13) return PngFastResult::kCorrupt;
      const PngFastResult layout = ReadHeader(data, pixels, &header);
      if (layout != PngFastResult::kDecoded) return layout;
      have_header = true;
    } else if (name == ChunkName("IDAT")) {
      if (idat_ended) return PngFastResult::kCorrupt;
      if (++idat_chunks == 1) {
        stream = {data, length};
      } else {
        if (idat_chunks == 2) idat_.assign(stream.begin(), stream.end());
        idat_.insert(idat_.end(), data, data + length);
        stream = idat_;
      }
    } else if (name == ChunkName("IEND")) {
      if (length != 0 || idat_chunks == 0) return PngFastResult::kCorrupt;
      break;  // libpng reads nothing after IEND either
    } else if (name == ChunkName("IHDR")) {
      return PngFastResult::kCorrupt;
    } else if (!IsMetadata(name)) {
      return PngFastResult::kUnsupported;
    } else {
      idat_ended = idat_chunks > 0;
    }
  }

  // Inflate every row, each with its filter-type byte, into one buffer of the exact size the
  // header implies: libdeflate checks the Adler-32 and fails on a stream of another length.
  const std::size_t bpp = static_cast<std::size_t>(header.channels * header.depth / 8);
  const std::size_t row_bytes = header.width * bpp;
  const std::size_t stride = row_bytes + 1;
  const std::size_t inflated_size = header.height * stride;
  if (inflated_size / kPngMaxInflateRatio > stream.size()) return PngFastResult::kCorrupt;
  filtered_.resize(inflated_size);
  std::size_t consumed = 0;
  if (libdeflate_zlib_decompress_ex(inflater_, stream.data(), stream.size(), filtered_.data(),
                                    inflated_size, &consumed, nullptr) != LIBDEFLATE_SUCCESS ||
      consumed != stream.size())
    return PngFastResult::kCorrupt;

  // Unfilter each row into the image, against the row above already unfiltered there; rows
  // of 16-bit grey chopped to 8 bits are unfiltered in place first, then their high bytes kept.
  const bool chop = header.depth == 16 && pixels == PngPixels::kGrey8;
  const int depth = header.depth == 16 && !chop ? CV_16U : CV_8U;
  image->create(static_cast<int>(header.height), static_cast<int>(header.width),
                CV_MAKETYPE(depth, header.channels));
  zero_row_.assign(row_bytes, 0);
  const unsigned char* prior = zero_row_.data();
  for (std::size_t y = 0; y < header.height; ++y) {
    unsigned char* in = &filtered_[y * stride];
    unsigned char* out = chop ? in + 1 : image->ptr(static_cast<int>(y));
    if (!Unfilter(in[0], in + 1, prior, out, row_bytes, bpp)) return PngFastResult::kCorrupt;
    prior = out;
  }
  if (chop) {
    for (std::size_t y = 0; y < header.height; ++y) {
      const unsigned char* in = &filtered_[y * stride + 1];
      unsigned char* out = image->ptr(static_cast<int>(y));
      for (std::size_t x = 0; x < header.width; ++x) out[x] = in[2 * x];
    }
  } else if (header.depth == 16 || header.channels > 1) {
    ToOpenCvOrder(image);
  }
  return PngFastResult::kDecoded;
}

}  // namespace cslam
