#include "system/io/png_codec.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <string>
#include <memory>
#include <stdexcept>

#include "core/errors.h"
#include "system/io/png_fast_decode.h"

namespace cslam {

namespace {

// libpng reports errors by calling back and never returning: the callback keeps the message
// and jumps back to the setjmp of the call that started the work. Only C frames and frames
// with trivially destructible locals (ReadImage, ReadBytes, WriteImage) lie between, so the
// jump skips no destructor; everything with one lives in the caller's Job, created before
// setjmp.
void OnError(png_structp png, png_const_charp message) {
  if (auto* error = static_cast<std::string*>(png_get_error_ptr(png)))
    *error = message ? message : "unknown libpng error";
  png_longjmp(png, 1);
}

// imread lets libpng print warnings (an sRGB profile libpng dislikes) to stderr; the pixels
// are read all the same, and a run's console is no place for them.
void OnWarning(png_structp, png_const_charp) {}

struct ReadJob {
  PngPixels pixels = PngPixels::kGrey8;
  std::span<const unsigned char> bytes;  // the whole file
  std::size_t read = 0;                  // how much of it libpng has taken
  cv::Mat image;
  std::vector<png_bytep> rows;
  std::string error;
};

void ReadBytes(png_structp png, png_bytep data, png_size_t size) {
  auto* job = static_cast<ReadJob*>(png_get_io_ptr(png));
  if (size > job->bytes.size() - job->read) png_error(png, "unexpected end of file");
  std::memcpy(data, job->bytes.data() + job->read, size);
  job->read += size;
}

bool LittleEndian() {
  const unsigned short one = 1;
  return *reinterpret_cast<const unsigned char*>(&one) == 1;
}

// The transformations imread asks of libpng for the same request, then the pixels.
void ReadImage(png_structp png, png_infop info, ReadJob* job) {
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int depth = 0, colour = 0;
  png_get_IHDR(png, info, &width, &height, &depth, &colour, nullptr, nullptr, nullptr);
  // The image is allocated before its data is read: a header must not claim more pixels than
  // the file's compressed data could hold (DEFLATE expands at most 1032:1), or a 60-byte file
  // allocates gigabytes.
  const double raw_bytes = static_cast<double>(height) * (static_cast<double>(png_get_rowbytes(png, info)) + 1);
  const double max_bytes = static_cast<double>(kPngMaxInflateRatio) * static_cast<double>(job->bytes.size());
  if (raw_bytes > max_bytes + 4096)
    png_error(png, "the header claims more pixels than the file's data can hold");
  const bool has_colour = (colour & PNG_COLOR_MASK_COLOR) != 0;
  int channels = 1;
  if (job->pixels == PngPixels::kUnchanged) {
    const bool alpha = (colour & PNG_COLOR_MASK_ALPHA) != 0 ||
                       (has_colour && png_get_valid(png, info, PNG_INFO_tRNS));
    channels = alpha ? 4 : has_colour ? 3 : 1;
  }
  const bool sixteen = depth == 16 && job->pixels != PngPixels::kGrey8;
  if (depth == 16 && !sixteen) png_set_strip_16(png);
  if (sixteen && LittleEndian()) png_set_swap(png);
  if (channels < 4)
    png_set_strip_alpha(png);
  else
    png_set_tRNS_to_alpha(png);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (!has_colour && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (channels > 1 && has_colour)
    png_set_bgr(png);
  else if (channels > 1)
    png_set_gray_to_rgb(png);
  else if (has_colour)
    png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const int type = CV_MAKETYPE(sixteen ? CV_16U : CV_8U, channels);
  const size_t row_bytes = static_cast<size_t>(width) * CV_ELEM_SIZE(type);
  if (png_get_rowbytes(png, info) != row_bytes)
    png_error(png, "unexpected row size after conversion (unsupported PNG layout)");
  job->image.create(static_cast<int>(height), static_cast<int>(width), type);
  job->rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) job->rows[y] = job->image.ptr(static_cast<int>(y));
  png_read_image(png, job->rows.data());
  png_read_end(png, nullptr);
}

bool Read(ReadJob* job) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job->error, OnError, OnWarning);
  if (!png) {
    job->error = "libpng could not start (out of memory)";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    job->error = "libpng could not start (out of memory)";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, job, ReadBytes);
  // No chunk is larger than the file that holds it; decompressed text and profiles get room
  // beyond that, but not the gigabytes a corrupt length or a zip bomb would claim.
  png_set_chunk_malloc_max(png, std::max<png_alloc_size_t>(job->bytes.size(), 8u << 20));
  ReadImage(png, info, job);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

struct WriteJob {
  const cv::Mat* image = nullptr;
  std::vector<png_bytep> rows;
  std::vector<unsigned char> bytes;
  std::string error;
};

void Append(png_structp png, png_bytep data, png_size_t size) {
  auto* job = static_cast<WriteJob*>(png_get_io_ptr(png));
  try {
    job->bytes.insert(job->bytes.end(), data, data + size);
  } catch (const std::bad_alloc&) {
    png_error(png, "out of memory");
  }
}

void Flush(png_structp) {}

void WriteImage(png_structp png, png_infop info, WriteJob* job) {
  const cv::Mat& image = *job->image;
  const int channels = image.channels();
  const int colour = channels == 1   ? PNG_COLOR_TYPE_GRAY
                     : channels == 3 ? PNG_COLOR_TYPE_RGB
                                     : PNG_COLOR_TYPE_RGB_ALPHA;
  const bool sixteen = image.depth() == CV_16U;
  png_set_write_fn(png, job, Append, Flush);
  // What imencode uses by default: fastest deflate level, run-length strategy.
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows),
               sixteen ? 16 : 8, colour, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (channels > 1) png_set_bgr(png);
  if (sixteen && LittleEndian()) png_set_swap(png);
  job->rows.resize(static_cast<size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y)
    job->rows[static_cast<size_t>(y)] = const_cast<png_bytep>(image.ptr(y));
  png_write_image(png, job->rows.data());
  png_write_end(png, nullptr);
}

bool Write(WriteJob* job) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job->error, OnError, OnWarning);
  if (!png) {
    job->error = "libpng could not start (out of memory)";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    job->error = "libpng could not start (out of memory)";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  WriteImage(png, info, job);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// Reads the file at `path` into `buffer`, which is grown but never shrunk (it is kept for the
// next file), and returns the file's length.
std::size_t ReadFile(const std::string& path, std::vector<unsigned char>* buffer) {
  const std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw InputError(path, "cannot open the image file");
  constexpr std::size_t kBlock = 1 << 16;
  std::size_t size = 0;
  for (;;) {
    if (buffer->size() - size < kBlock) buffer->resize(std::max(2 * buffer->size(), size + kBlock));
    const std::size_t got = std::fread(buffer->data() + size, 1, buffer->size() - size, file.get());
    size += got;
    if (got == 0) break;
  }
  if (std::ferror(file.get())) throw InputError(path, "cannot read the image file");
  return size;
}

}  // namespace

cv::Mat ReadPng(const std::string& path, PngPixels pixels) {
  // Kept per thread between files: the dataset readers decode two images of the same size
  // per frame, and fresh buffers of that size cost page faults on every one.
  thread_local std::vector<unsigned char> buffer;
  thread_local PngFastDecoder fast;
  // Read first: the read may grow (move) the buffer, and the span must see where it ends up.
  const std::size_t size = ReadFile(path, &buffer);
  const std::span<const unsigned char> bytes(buffer.data(), size);
  cv::Mat image;
  if (fast.Decode(bytes, pixels, &image) == PngFastResult::kDecoded) return image;
  return DecodePngWithLibpng(bytes, pixels, path);
}

cv::Mat DecodePngWithLibpng(std::span<const unsigned char> bytes, PngPixels pixels,
                            const std::string& name) {
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0)
    throw InputError(name, "cannot decode the image: not a PNG file");
  // libpng allocates a chunk's claimed length before reading it (2 GB for a corrupt text
  // chunk's length, whatever png_set_chunk_malloc_max says): no chunk may run past the file.
  for (std::size_t at = 8; bytes.size() - at >= 8;) {
    const std::uint64_t length = PngBigEndian32(&bytes[at]);
    if (length + 12 > bytes.size() - at)
      throw InputError(name, "cannot decode the image (corrupt PNG: the chunk at byte " +
                                 std::to_string(at) + " claims " + std::to_string(length) +
                                 " bytes, past the end of the file)");
    if (std::memcmp(&bytes[at + 4], "IEND", 4) == 0) break;
    at += 12 + length;
  }
  ReadJob job;
  job.pixels = pixels;
  job.bytes = bytes;
  if (!Read(&job))
    throw InputError(name, "cannot decode the image (corrupt PNG: " + job.error + ")");
  return job.image;
}

std::vector<unsigned char> EncodePng(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("cannot encode an empty image as PNG");
  const int depth = image.depth(), channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4))
    throw std::invalid_argument("PNG holds 8- or 16-bit images with 1, 3 or 4 channels; got " +
                                cv::typeToString(image.type()));
  WriteJob job;
  job.image = &image;
  if (!Write(&job)) throw std::runtime_error("PNG encoding failed: " + job.error);
  return std::move(job.bytes);
}

}  // namespace cslam
