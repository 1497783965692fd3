#pragma once
// Small fixed-size patches sampled from 8-bit grey images, and their normalised
// cross-correlation: the photometric check shared by the stereo matcher and the tracker.
#include <opencv2/core/mat.hpp>
#include <vector>

namespace cslam {

/// A size×size float patch centred on a sub-pixel image point (row-major).
struct ImagePatch {
  int size = 0;
  std::vector<float> values;
};

/// Samples `size`×`size` pixels (odd size) centred on (x, y) with bilinear interpolation.
/// Returns false, leaving `patch` unspecified, when any sample would fall outside the image.
/// Precondition: `grey` is CV_8UC1.
bool SamplePatch(const cv::Mat& grey, float x, float y, int size, ImagePatch* patch);

/// Normalised cross-correlation in [-1, 1] of two patches of equal size; 0 when either patch
/// is flat (no texture cannot confirm a match).
double Ncc(const ImagePatch& a, const ImagePatch& b);

/// A patch prepared for repeated NCC against many windows: zero mean, with its norm.
struct NccTemplate {
  int size = 0;
  std::vector<float> zero_mean;
  double norm = 0;  ///< 0 when the patch is flat
};
NccTemplate PrepareNcc(const ImagePatch& patch);
/// As above, into `templ`, reusing its storage (no allocation once it has grown).
void PrepareNcc(const ImagePatch& patch, NccTemplate* templ);

/// NCC of `templ` against the window of the same size whose top-left corner is (x0, y0) in
/// `strip` (a row-major float image of width `strip_width`); 0 when either side is flat.
double NccAt(const NccTemplate& templ, const std::vector<float>& strip, int strip_width, int x0,
             int y0);

/// Largest `count` of NccAlongX / NccAlongY.
inline constexpr int kMaxNccShifts = 64;

/// `out[s]` = NccAt(templ, strip, strip_width, s, 0) for s = 0..count−1 (count <= kMaxNccShifts),
/// bit for bit: every shift's sums are accumulated in NccAt's order, but all shifts advance in
/// one pass over the template, so the inner loop runs over shifts (vectorisable).
void NccAlongX(const NccTemplate& templ, const std::vector<float>& strip, int strip_width,
               int count, double* out);

/// `out[s]` = NccAt(templ, strip, strip_width, 0, s) for s = 0..count−1, as NccAlongX.
void NccAlongY(const NccTemplate& templ, const std::vector<float>& strip, int strip_width,
               int count, double* out);

/// Samples a `width`×`height` float strip with top-left sample at (x, y) (sub-pixel,
/// bilinear). Returns false when it does not fit inside the image.
bool SampleStrip(const cv::Mat& grey, float x, float y, int width, int height,
                 std::vector<float>* strip);

/// As SampleStrip, but interpolating along x with the Keys cubic kernel (a = −0.5; linear
/// along y). Bilinear interpolation delays a wave of period λ by a fraction-dependent amount
/// (at fraction 0.25 and λ = 3 px it lags by 0.08 px), which pulls sub-pixel estimates towards
/// whole pixels; the cubic kernel's lag is a few times smaller. Returns false when the 4-tap
/// support does not fit inside the image.
bool SampleStripCubicX(const cv::Mat& grey, float x, float y, int width, int height,
                       std::vector<float>* strip);

}  // namespace cslam
