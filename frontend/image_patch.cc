#include "frontend/image_patch.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/errors.h"

namespace cslam {
namespace {
// Strips up to this width use the row-buffered path of SampleStrip (stack buffers).
constexpr int kMaxFastStripWidth = 128;
}  // namespace

bool SampleStrip(const cv::Mat& grey, float x, float y, int width, int height,
                 std::vector<float>* strip) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  // +1 for the bilinear neighbour; NaN coordinates fail the comparisons as well.
  if (!(x0 >= 0 && y0 >= 0 && x0 + width < grey.cols && y0 + height < grey.rows)) return false;
  const float fx = x - x0, fy = y - y0;
  const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
  strip->resize(static_cast<size_t>(width) * height);
  float* out = strip->data();
  if (width > kMaxFastStripWidth) {
    for (int r = 0; r < height; ++r) {
      const uint8_t* a = grey.ptr<uint8_t>(y0 + r) + x0;
      const uint8_t* b = grey.ptr<uint8_t>(y0 + r + 1) + x0;
      for (int c = 0; c < width; ++c)
        *out++ = w00 * a[c] + w01 * a[c + 1] + w10 * b[c] + w11 * b[c + 1];
    }
    return true;
  }
  // Each image row is converted to float once (it is the lower row of one output row and the
  // upper row of the next); the weighted sum over floats then vectorises. Same operations in
  // the same order as the loop above, so the same values bit for bit.
  float rows[2][kMaxFastStripWidth + 1];
  float* upper = rows[0];
  float* lower = rows[1];
  const auto convert = [&](int y, float* dst) {
    const uint8_t* src = grey.ptr<uint8_t>(y) + x0;
    for (int c = 0; c <= width; ++c) dst[c] = src[c];
  };
  convert(y0, upper);
  for (int r = 0; r < height; ++r, out += width) {
    convert(y0 + r + 1, lower);
    for (int c = 0; c < width; ++c)
      out[c] = w00 * upper[c] + w01 * upper[c + 1] + w10 * lower[c] + w11 * lower[c + 1];
    std::swap(upper, lower);
  }
  return true;
}

bool SampleStripCubicX(const cv::Mat& grey, float x, float y, int width, int height,
                       std::vector<float>* strip) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  if (!(x0 >= 1 && y0 >= 0 && x0 + width + 1 < grey.cols && y0 + height < grey.rows)) return false;
  const float t = x - x0, fy = y - y0;
  // Keys (1981) cubic convolution weights of the samples at x0 − 1 … x0 + 2, a = −0.5.
  const float t2 = t * t, t3 = t2 * t;
  const float w[4] = {-0.5f * t3 + t2 - 0.5f * t, 1.5f * t3 - 2.5f * t2 + 1.f,
                      -1.5f * t3 + 2.f * t2 + 0.5f * t, 0.5f * t3 - 0.5f * t2};
  strip->resize(static_cast<size_t>(width) * height);
  float* out = strip->data();
  for (int r = 0; r < height; ++r) {
    const uint8_t* a = grey.ptr<uint8_t>(y0 + r) + x0 - 1;
    const uint8_t* b = grey.ptr<uint8_t>(y0 + r + 1) + x0 - 1;
    for (int c = 0; c < width; ++c) {
      const float top = w[0] * a[c] + w[1] * a[c + 1] + w[2] * a[c + 2] + w[3] * a[c + 3];
      const float bottom = w[0] * b[c] + w[1] * b[c + 1] + w[2] * b[c + 2] + w[3] * b[c + 3];
      *out++ = (1 - fy) * top + fy * bottom;
    }
  }
  return true;
}

bool SamplePatch(const cv::Mat& grey, float x, float y, int size, ImagePatch* patch) {
  const float half = static_cast<float>(size / 2);
  patch->size = size;
  return SampleStrip(grey, x - half, y - half, size, size, &patch->values);
}

namespace {
// A window whose variance is below ~0.5 grey level² per pixel is flat: it carries no evidence.
constexpr double kFlatVariance = 0.5;

double NccOfWindows(const float* a, int a_stride, const float* b, int b_stride, int size) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int r = 0; r < size; ++r) {
    const float* pa = a + r * a_stride;
    const float* pb = b + r * b_stride;
    for (int c = 0; c < size; ++c) {
      const double va = pa[c], vb = pb[c];
      sa += va;
      sb += vb;
      saa += va * va;
      sbb += vb * vb;
      sab += va * vb;
    }
  }
  const double n = static_cast<double>(size) * size;
  const double var_a = saa - sa * sa / n, var_b = sbb - sb * sb / n;
  if (var_a < kFlatVariance * n || var_b < kFlatVariance * n) return 0.0;
  return (sab - sa * sb / n) / std::sqrt(var_a * var_b);
}
}  // namespace

double Ncc(const ImagePatch& a, const ImagePatch& b) {
  if (a.size != b.size || a.size <= 0) return 0.0;
  return NccOfWindows(a.values.data(), a.size, b.values.data(), b.size, a.size);
}

NccTemplate PrepareNcc(const ImagePatch& patch) {
  NccTemplate t;
  PrepareNcc(patch, &t);
  return t;
}

void PrepareNcc(const ImagePatch& patch, NccTemplate* templ) {
  NccTemplate& t = *templ;
  t.size = patch.size;
  const double n = static_cast<double>(patch.size) * patch.size;
  double mean = 0;
  for (float v : patch.values) mean += v;
  mean /= n;
  double norm2 = 0;
  t.zero_mean.resize(patch.values.size());
  for (size_t k = 0; k < patch.values.size(); ++k) {
    t.zero_mean[k] = static_cast<float>(patch.values[k] - mean);
    norm2 += static_cast<double>(t.zero_mean[k]) * t.zero_mean[k];
  }
  t.norm = norm2 < kFlatVariance * n ? 0.0 : std::sqrt(norm2);
}

double NccAt(const NccTemplate& templ, const std::vector<float>& strip, int strip_width, int x0,
             int y0) {
  if (templ.norm == 0) return 0.0;
  const int size = templ.size;
  // Σ t̃·r equals Σ t̃·(r − r̄) because Σ t̃ = 0, so only the window's variance is needed.
  float sr = 0, srr = 0, str = 0;
  for (int r = 0; r < size; ++r) {
    const float* w = strip.data() + static_cast<size_t>(y0 + r) * strip_width + x0;
    const float* t = templ.zero_mean.data() + r * size;
    for (int c = 0; c < size; ++c) {
      sr += w[c];
      srr += w[c] * w[c];
      str += t[c] * w[c];
    }
  }
  const double n = static_cast<double>(size) * size;
  const double var = static_cast<double>(srr) - static_cast<double>(sr) * sr / n;
  if (var < kFlatVariance * n) return 0.0;
  return str / (templ.norm * std::sqrt(var));
}

namespace {
/// NCC from the window sums of NccAt.
double NccFromSums(const NccTemplate& templ, float sr, float srr, float str) {
  const double n = static_cast<double>(templ.size) * templ.size;
  const double var = static_cast<double>(srr) - static_cast<double>(sr) * sr / n;
  if (var < kFlatVariance * n) return 0.0;
  return str / (templ.norm * std::sqrt(var));
}

/// The sums of NccAt for `count` windows whose top-left corners are `step` floats apart in
/// `strip`; each window's sums are accumulated in NccAt's (row, column) order.
void NccOfShifts(const NccTemplate& templ, const std::vector<float>& strip, int strip_width,
                 int count, int step, double* out) {
  CSLAM_CHECK(count >= 0 && count <= kMaxNccShifts, "NccAlongX/Y: count out of range");
  if (templ.norm == 0) {
    std::fill(out, out + count, 0.0);
    return;
  }
  const int size = templ.size;
  CSLAM_CHECK(static_cast<size_t>((size - 1) * strip_width + size) +
                      static_cast<size_t>(count - 1) * step <=
                  strip.size(),
              "NccAlongX/Y: strip too small");
  float sr[kMaxNccShifts] = {}, srr[kMaxNccShifts] = {}, str[kMaxNccShifts] = {};
  for (int r = 0; r < size; ++r) {
    const float* w = strip.data() + static_cast<size_t>(r) * strip_width;
    const float* t = templ.zero_mean.data() + r * size;
    for (int c = 0; c < size; ++c) {
      const float tc = t[c];
      const float* wc = w + c;
      for (int s = 0; s < count; ++s) {
        const float v = wc[s * step];
        sr[s] += v;
        srr[s] += v * v;
        str[s] += tc * v;
      }
    }
  }
  for (int s = 0; s < count; ++s) out[s] = NccFromSums(templ, sr[s], srr[s], str[s]);
}
}  // namespace

void NccAlongX(const NccTemplate& templ, const std::vector<float>& strip, int strip_width,
               int count, double* out) {
  NccOfShifts(templ, strip, strip_width, count, 1, out);
}

void NccAlongY(const NccTemplate& templ, const std::vector<float>& strip, int strip_width,
               int count, double* out) {
  NccOfShifts(templ, strip, strip_width, count, strip_width, out);
}

}  // namespace cslam
