#include "frontend/stereo_matcher.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/options_reader.h"
#include "core/task_runner.h"
#include "frontend/image_patch.h"

namespace cslam {

void StereoMatcherOptions::Check() const {
  CheckOption(min_disparity_px > 0, "min_disparity_px", "must be > 0 px", min_disparity_px);
  CheckOption(max_disparity_px > min_disparity_px, "max_disparity_px", "must be > min_disparity_px",
              max_disparity_px);
  CheckOption(coarse_patch_px >= 3 && coarse_patch_px % 2 == 1, "coarse_patch_px",
              "must be odd and >= 3 px", coarse_patch_px);
  CheckOption(max_ambiguity > 0 && max_ambiguity <= 1, "max_ambiguity", "must be in (0, 1]",
              max_ambiguity);
  CheckOption(refine_radius_px >= 2 && refine_radius_px <= 31, "refine_radius_px",
              "must be in [2, 31] px (the coarse step is 2 px)", refine_radius_px);
  CheckOption(patch_px >= 3 && patch_px % 2 == 1, "patch_px", "must be odd and >= 3 px", patch_px);
  CheckOption(min_ncc >= -1 && min_ncc <= 1, "min_ncc", "must be in [-1, 1]", min_ncc);
  CheckOption(max_row_error_px > 0, "max_row_error_px", "must be > 0 px", max_row_error_px);
  CheckOption(max_hamming >= 0 && max_hamming <= 256, "max_hamming", "must be in [0, 256] bits",
              max_hamming);
  CheckOption(prior_margin_px >= 2, "prior_margin_px", "must be >= 2 px (the coarse step)",
              prior_margin_px);
  CheckOption(prior_margin_ratio >= 0, "prior_margin_ratio", "must be >= 0", prior_margin_ratio);
  CheckOption(std::isfinite(disparity_offset_px) && std::abs(disparity_offset_px) < 5,
              "disparity_offset_px", "must be finite and within ±5 px", disparity_offset_px);
  if (subpixel != "lk" && subpixel != "parabola")
    throw ConfigError("subpixel", "must be \"lk\" or \"parabola\", got \"" + subpixel + "\"");
}

void StereoMatcherOptions::Load(OptionsReader& reader) {
  reader.Read("min_disparity_px", &min_disparity_px);
  reader.Read("max_disparity_px", &max_disparity_px);
  reader.Read("coarse_patch_px", &coarse_patch_px);
  reader.Read("max_ambiguity", &max_ambiguity);
  reader.Read("unique_match", &unique_match);
  reader.Read("refine_radius_px", &refine_radius_px);
  reader.Read("patch_px", &patch_px);
  reader.Read("min_ncc", &min_ncc);
  reader.Read("max_row_error_px", &max_row_error_px);
  reader.Read("max_hamming", &max_hamming);
  reader.Read("prior_margin_px", &prior_margin_px);
  reader.Read("prior_margin_ratio", &prior_margin_ratio);
  reader.Read("subpixel", &subpixel);
  reader.Read("disparity_offset_px", &disparity_offset_px);
}

namespace {
constexpr int kOrbBytes = 32;
constexpr int kOrbPatch = 31;
// ORB's sampling pattern reaches ~15 px (patch 31) from the keypoint; +1 for rounding.
constexpr int kOrbEdge = 16;

int Hamming(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int k = 0; k < kOrbBytes; k += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}

/// Vertex offset of the parabola through (−1, cm), (0, c0), (+1, cp); 0 when not concave.
double ParabolaPeak(double cm, double c0, double cp) {
  const double curvature = cm - 2 * c0 + cp;
  return curvature < 0 ? 0.5 * (cm - cp) / curvature : 0.0;
}

/// Sub-pixel disparity by Gauss-Newton alignment along x. The NCC parabola's vertex is biased
/// towards the integer sample it is fitted around (the peak of a correlation is not a
/// parabola), by up to ~0.1 px; this aligns the windows themselves instead. Both windows are
/// sampled with cubic interpolation along x (bilinear sampling has its own whole-pixel pull),
/// made zero-mean and scaled to the template's norm (the gain/offset invariance of NCC), and
/// each step uses the mean of both windows' x-gradients (efficient second-order minimisation),
/// which converges in 2–3 steps and keeps the update symmetric in the two images.
class SubPixelAligner {
 public:
  /// Left template centred on (x, y). False when the template does not fit or is flat.
  bool SetTemplate(const cv::Mat& left, float x, float y, int size) {
    size_ = size;
    if (!SampleStripCubicX(left, x - size / 2 - 1, y - size / 2, size + 2, size, &buf_))
      return false;
    Normalise(buf_, &templ_, &templ_dx_, 0.0);
    return templ_norm_ > 0;
  }

  /// Refines the right column `*u` (of the template's centre) on row `y`. Returns false, with
  /// `*u` unchanged, when the window leaves the image, is flat, or the iteration moves more
  /// than `max_move_px` from the start (no nearby optimum).
  bool Refine(const cv::Mat& right, float y, double max_move_px, double* u) {
    const int n = size_ * size_;
    double x = *u;
    for (int it = 0; it < kMaxIterations; ++it) {
      if (!SampleStripCubicX(right, static_cast<float>(x) - size_ / 2 - 1, y - size_ / 2,
                             size_ + 2, size_, &buf_))
        return false;
      if (!Normalise(buf_, &win_, &win_dx_, templ_norm_)) return false;
      double num = 0, den = 0;
      for (int k = 0; k < n; ++k) {
        const double g = 0.5 * (templ_dx_[k] + win_dx_[k]);
        num += g * (win_[k] - templ_[k]);
        den += g * g;
      }
      if (!(den > 0)) return false;
      // W(ξ; x) ≈ T(ξ + x − x*) ⇒ W − T ≈ (x − x*) g.
      const double step = -num / den;
      x += std::clamp(step, -0.5, 0.5);
      if (std::abs(x - *u) > max_move_px) return false;
      if (std::abs(step) < kConvergedPx) break;
    }
    *u = x;
    return true;
  }

 private:
  static constexpr int kMaxIterations = 10;
  static constexpr double kConvergedPx = 1e-3;

  /// Inner size×size window of a (size+2)×size strip made zero-mean (and scaled to norm
  /// `target`, or left as is and its norm stored when target is 0), with central x-gradients.
  bool Normalise(const std::vector<float>& strip, std::vector<double>* values,
                 std::vector<double>* dx, double target) {
    const int w = size_ + 2, n = size_ * size_;
    values->resize(n);
    dx->resize(n);
    double mean = 0;
    for (int r = 0; r < size_; ++r)
      for (int c = 0; c < size_; ++c) mean += strip[r * w + c + 1];
    mean /= n;
    double norm2 = 0;
    for (int r = 0; r < size_; ++r)
      for (int c = 0; c < size_; ++c) {
        const int k = r * size_ + c;
        (*values)[k] = strip[r * w + c + 1] - mean;
        (*dx)[k] = 0.5 * (strip[r * w + c + 2] - strip[r * w + c]);
        norm2 += (*values)[k] * (*values)[k];
      }
    // The flatness floor of image_patch's NCC: ~0.7 grey levels of contrast.
    if (norm2 < 0.5 * n) {
      if (target == 0) templ_norm_ = 0;
      return false;
    }
    const double norm = std::sqrt(norm2);
    if (target == 0) {
      templ_norm_ = norm;
      return true;
    }
    const double scale = target / norm;
    for (int k = 0; k < n; ++k) {
      (*values)[k] *= scale;
      (*dx)[k] *= scale;
    }
    return true;
  }

  int size_ = 0;
  double templ_norm_ = 0;
  std::vector<float> buf_;
  std::vector<double> templ_, templ_dx_, win_, win_dx_;
};

/// Zero-mean NCC of a coarse template against every column of a right-image row band, with
/// the window sums taken from column sums so each candidate costs one dot product.
class CoarseSearch {
 public:
  /// Fills `scores[k]` for right window centres c_lo + k, k = 0..c_hi − c_lo. Returns false
  /// when the template is flat.
  bool Run(const cv::Mat& left1, const cv::Mat& right1, int cl, int row, int c_lo, int c_hi,
           int size, std::vector<double>* scores) {
    const int h = size / 2;
    const double n = static_cast<double>(size) * size;
    templ_.resize(static_cast<size_t>(size) * size);
    double mean = 0;
    for (int r = 0; r < size; ++r) {
      const uint8_t* src = left1.ptr<uint8_t>(row - h + r) + cl - h;
      for (int c = 0; c < size; ++c) mean += (templ_[r * size + c] = src[c]);
    }
    mean /= n;
    double norm2 = 0;
    for (float& t : templ_) {
      t = static_cast<float>(t - mean);
      norm2 += static_cast<double>(t) * t;
    }
    if (norm2 < 0.5 * n) return false;  // < ~0.7 grey levels of contrast: nothing to match
    const double norm = std::sqrt(norm2);

    // Prefix sums over columns of the band of the right window sums Σr and Σr².
    const int x0 = c_lo - h, width = c_hi - c_lo + size;
    // Integer sums (exact, as the doubles they replace were): the column loop runs over x
    // inside the row loop, so it is contiguous and vectorisable.
    col_sum_.assign(width, 0);
    col_sq_.assign(width, 0);
    for (int r = 0; r < size; ++r) {
      const uint8_t* src = right1.ptr<uint8_t>(row - h + r) + x0;
      int32_t* cs = col_sum_.data();
      int32_t* cq = col_sq_.data();
      for (int x = 0; x < width; ++x) {
        const int32_t v = src[x];
        cs[x] += v;
        cq[x] += v * v;
      }
    }
    sum_.resize(width + 1);
    sq_.resize(width + 1);
    sum_[0] = 0;
    sq_[0] = 0;
    for (int x = 0; x < width; ++x) {
      sum_[x + 1] = sum_[x] + col_sum_[x];
      sq_[x + 1] = sq_[x] + col_sq_[x];
    }
    // Σ t·r for every candidate at once: the inner loop runs over candidates (contiguous,
    // vectorisable), the outer over template pixels.
    const int count = c_hi - c_lo + 1;
    dot_.assign(count, 0);
    for (int r = 0; r < size; ++r) {
      const uint8_t* band = right1.ptr<uint8_t>(row - h + r) + x0;
      const uint8_t* trow = left1.ptr<uint8_t>(row - h + r) + cl - h;
      for (int c = 0; c < size; ++c) {
        const int32_t t = trow[c];
        const uint8_t* src = band + c;
        int32_t* acc = dot_.data();
        for (int k = 0; k < count; ++k) acc[k] += t * src[k];
      }
    }
    scores->resize(count);
    for (int k = 0; k < count; ++k) {
      const double s = static_cast<double>(sum_[k + size] - sum_[k]),
                   q = static_cast<double>(sq_[k + size] - sq_[k]);
      const double var = q - s * s / n;
      // Σ (t − t̄)·r = Σ t·r − t̄·Σ r; flat right windows score 0.
      (*scores)[k] = var < 0.5 * n ? 0.0 : (dot_[k] - mean * s) / (norm * std::sqrt(var));
    }
    return true;
  }

 private:
  std::vector<float> templ_;
  std::vector<int64_t> sum_, sq_;
  std::vector<int32_t> col_sum_, col_sq_, dot_;
};

cv::Ptr<cv::ORB> MakeOrb() {
  // One level and upright descriptors: rectified views differ by neither rotation nor scale.
  return cv::ORB::create(/*nfeatures=*/1, /*scaleFactor=*/1.2f, /*nlevels=*/1,
                         /*edgeThreshold=*/kOrbEdge, /*firstLevel=*/0, /*WTA_K=*/2,
                         cv::ORB::HARRIS_SCORE, kOrbPatch, /*fastThreshold=*/20);
}

// The buffers of one part of a call's points (parts run side by side, each with its own).
struct Scratch {
  CoarseSearch coarse;
  std::vector<double> scores;
  std::vector<float> strip, column, other_strip;
  std::vector<int> other_peaks;  // coarse indices of the other peaks that reach min_ncc
  // The part's matches whose descriptors decide them (class_id: the point's index).
  std::vector<cv::KeyPoint> left_kp, right_kp;
  ImagePatch patch;
  NccTemplate templ;
  SubPixelAligner aligner;

  // Does one of other_peaks pass the photometric check at full resolution? templ holds the
  // left window of the point p; cl and c_lo place the coarse search as in Match.
  bool AnotherMatchPasses(const cv::Mat& right_grey, cv::Point2f p, int cl, int c_lo,
                          const StereoMatcherOptions& o) {
    const int half = o.patch_px / 2, radius = o.refine_radius_px;
    const int strip_w = o.patch_px + 2 * radius;
    double ncc[kMaxNccShifts] = {};
    for (int k : other_peaks) {
      const double u = p.x - 2.0 * (cl - (c_lo + k));
      if (!SampleStrip(right_grey, static_cast<float>(u - radius - half), p.y - half, strip_w,
                       o.patch_px, &other_strip))
        continue;
      NccAlongX(templ, other_strip, strip_w, 2 * radius + 1, ncc);
      if (*std::max_element(ncc, ncc + 2 * radius + 1) >= o.min_ncc) return true;
    }
    return false;
  }
};

// Points per part below which a part is not worth a thread's start.
constexpr int kMinPointsPerPart = 64;
// Parts per call: more than the threads, so that a part of costly points (a textured region
// searched over the whole disparity range) does not hold back the others.
constexpr int kMaxParts = 4;

}  // namespace

struct StereoMatcher::Impl {
  cv::Ptr<cv::ORB> orb_left = MakeOrb(), orb_right = MakeOrb();
  cv::Mat left1, right1;
  std::vector<Scratch> parts;
};

StereoMatcher::StereoMatcher(const StereoMatcherOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  options_.Check();
}
StereoMatcher::~StereoMatcher() = default;
StereoMatcher::StereoMatcher(StereoMatcher&&) noexcept = default;
StereoMatcher& StereoMatcher::operator=(StereoMatcher&&) noexcept = default;

namespace {

// Match's per-point search for points [begin, end): their results in `out`, and in the
// scratch's left_kp / right_kp the keypoints whose descriptors decide them.
void MatchPart(const cv::Mat& left_grey, const cv::Mat& right_grey, const cv::Mat& left1,
               const cv::Mat& right1, std::span<const cv::Point2f> left_points,
               std::span<const float> prior_disparity, const StereoMatcherOptions& o,
               size_t begin, size_t end, Scratch* scratch, std::vector<StereoMatch>* out) {
  Scratch& m = *scratch;
  m.left_kp.clear();
  m.right_kp.clear();
  const int ch = o.coarse_patch_px / 2;
  const int half = o.patch_px / 2;
  const int radius = o.refine_radius_px;
  const int d1_min = std::max(0, static_cast<int>(std::floor(o.min_disparity_px / 2)));
  const int d1_max = static_cast<int>(std::ceil(o.max_disparity_px / 2));
  const bool align = o.subpixel == "lk";
  for (size_t i = begin; i < end; ++i) {
    const cv::Point2f p = left_points[i];
    StereoMatch& res = (*out)[i];
    res.status = StereoReject::kOffImage;

    // Coarse: every disparity of the range at half resolution (pyrDown maps x → x/2).
    const int cl = static_cast<int>(std::lround(p.x / 2)),
              row = static_cast<int>(std::lround(p.y / 2));
    if (!(row - ch >= 0 && row + ch < left1.rows && cl - ch >= 0 && cl + ch < left1.cols))
      continue;
    // A tracked point's last disparity narrows where its match can be a frame later; with
    // unique_match the rest of the range is still scored, so that another period of a
    // repeated pattern is seen (stereo_matcher.h).
    int lo = d1_min, hi = d1_max;
    if (!prior_disparity.empty() && prior_disparity[i] > 0) {
      const double d = prior_disparity[i];
      const double margin = o.prior_margin_px + o.prior_margin_ratio * d;
      lo = std::max(d1_min, static_cast<int>(std::floor((d - margin) / 2)));
      hi = std::min(d1_max, static_cast<int>(std::ceil((d + margin) / 2)));
    }
    const int c_lo = std::max(ch, cl - (o.unique_match ? d1_max : hi));
    const int c_hi = std::min(right1.cols - 1 - ch, cl - (o.unique_match ? d1_min : lo));
    // The candidates the best match may be chosen from: indices [k_lo, k_hi] of the scores.
    const int k_lo = std::max(c_lo, cl - hi) - c_lo, k_hi = std::min(c_hi, cl - lo) - c_lo;
    if (c_hi < c_lo || k_hi < k_lo) {
      res.status = StereoReject::kNoCandidate;
      continue;
    }
    if (!m.coarse.Run(left1, right1, cl, row, c_lo, c_hi, o.coarse_patch_px, &m.scores)) {
      res.status = StereoReject::kPhotometric;
      continue;
    }
    const auto best_it = std::max_element(m.scores.begin() + k_lo, m.scores.begin() + k_hi + 1);
    const int k_best = static_cast<int>(best_it - m.scores.begin());
    // Second peak: the best score at least 2 coarse pixels from the best one.
    double second = -1;
    const int n_scores = static_cast<int>(m.scores.size());
    m.other_peaks.clear();
    for (int k = 0; k < n_scores; ++k) {
      if (std::abs(k - k_best) < 2) continue;
      const double s = m.scores[k];
      second = std::max(second, s);
      if (o.unique_match && s >= o.min_ncc && (k == 0 || s >= m.scores[k - 1]) &&
          (k + 1 == n_scores || s >= m.scores[k + 1]))
        m.other_peaks.push_back(k);
    }
    if (second > -1 && (1 - *best_it) > o.max_ambiguity * (1 - second)) {
      res.status = StereoReject::kAmbiguous;
      continue;
    }
    const double u0 = p.x - 2.0 * (cl - (c_lo + k_best));

    // Fine: 1-D NCC along x at full resolution around the coarse match, parabola at the peak.
    const int strip_w = o.patch_px + 2 * radius;
    if (!SamplePatch(left_grey, p.x, p.y, o.patch_px, &m.patch) ||
        !SampleStrip(right_grey, static_cast<float>(u0 - radius - half), p.y - half, strip_w,
                     o.patch_px, &m.strip))
      continue;
    PrepareNcc(m.patch, &m.templ);
    int s_best = 0;
    double fine[kMaxNccShifts] = {};
    NccAlongX(m.templ, m.strip, strip_w, 2 * radius + 1, fine);
    for (int s = 1; s <= 2 * radius; ++s)
      if (fine[s] > fine[s_best]) s_best = s;
    res.ncc = static_cast<float>(fine[s_best]);
    if (s_best == 0 || s_best == 2 * radius) {
      res.status = StereoReject::kNoPeak;
      continue;
    }
    if (res.ncc < o.min_ncc) {
      res.status = StereoReject::kPhotometric;
      continue;
    }
    if (m.AnotherMatchPasses(right_grey, p, cl, c_lo, o)) {
      res.status = StereoReject::kAmbiguous;
      continue;
    }
    const double cm = fine[s_best - 1], c0 = fine[s_best], cp = fine[s_best + 1];
    res.curvature = static_cast<float>(-(cm - 2 * c0 + cp));
    double u_right = u0 - radius + s_best + ParabolaPeak(cm, c0, cp);
    // The parabola starts the alignment within ~0.1 px of its optimum; a window that does not
    // converge within one pixel of it keeps the parabola's estimate.
    if (align && m.aligner.SetTemplate(left_grey, p.x, p.y, o.patch_px))
      m.aligner.Refine(right_grey, p.y, 1.0, &u_right);
    // The checks below look at the image; only the reported column carries the correction.
    const float u_image = static_cast<float>(u_right);
    res.u_right = static_cast<float>(u_right - o.disparity_offset_px);

    // Row error: NCC at rows −2..+2 around the refined match; the parabola vertex around the
    // best of the inner three is the vertical offset (a best row at ±2 means ≥ 1.5 px off).
    if (!SampleStrip(right_grey, u_image - half, p.y - half - 2, o.patch_px, o.patch_px + 4,
                     &m.column))
      continue;
    double vert[5];
    NccAlongY(m.templ, m.column, o.patch_px, 5, vert);
    const int v_best = static_cast<int>(std::max_element(vert, vert + 5) - vert);
    if (v_best == 0 || v_best == 4)
      res.row_error_px = v_best == 0 ? -2.f : 2.f;
    else
      res.row_error_px = static_cast<float>(
          v_best - 2 + ParabolaPeak(vert[v_best - 1], vert[v_best], vert[v_best + 1]));
    if (std::abs(res.row_error_px) > o.max_row_error_px) {
      res.status = StereoReject::kRowError;
      continue;
    }
    const double disparity = p.x - res.u_right;
    if (!(disparity >= o.min_disparity_px && disparity <= o.max_disparity_px)) {
      res.status = StereoReject::kDisparityRange;
      continue;
    }
    res.status = StereoReject::kDescriptorDistance;  // until the descriptors agree
    m.left_kp.emplace_back(p, static_cast<float>(kOrbPatch), 0.f, 0.f, 0, static_cast<int>(i));
    m.right_kp.emplace_back(cv::Point2f(u_image, p.y), static_cast<float>(kOrbPatch), 0.f, 0.f,
                            0, static_cast<int>(i));
  }
}

}  // namespace

std::vector<StereoMatch> StereoMatcher::Match(const cv::Mat& left_grey, const cv::Mat& right_grey,
                                              std::span<const cv::Point2f> left_points,
                                              std::span<const float> prior_disparity,
                                              const TaskRunner* runner) {
  CSLAM_CHECK(prior_disparity.empty() || prior_disparity.size() == left_points.size(),
              "one prior disparity per point, or none");
  Impl& m = *impl_;
  const StereoMatcherOptions& o = options_;
  std::vector<StereoMatch> out(left_points.size());
  if (left_points.empty()) return out;
  cv::pyrDown(left_grey, m.left1);
  cv::pyrDown(right_grey, m.right1);

  const size_t n = left_points.size();
  const int parts =
      runner ? static_cast<int>(std::clamp<size_t>(n / kMinPointsPerPart, 1, kMaxParts)) : 1;
  if (static_cast<int>(m.parts.size()) < parts) m.parts.resize(parts);
  RunTasks(runner, parts, [&](int j) {
    MatchPart(left_grey, right_grey, m.left1, m.right1, left_points, prior_disparity, o,
              n * j / parts, n * (j + 1) / parts, &m.parts[j], &out);
  });
  std::vector<cv::KeyPoint> left_kp, right_kp;
  for (int j = 0; j < parts; ++j) {
    left_kp.insert(left_kp.end(), m.parts[j].left_kp.begin(), m.parts[j].left_kp.end());
    right_kp.insert(right_kp.end(), m.parts[j].right_kp.begin(), m.parts[j].right_kp.end());
  }
  // Descriptor distance of the surviving matches (ORB drops keypoints too near the border).
  if (!left_kp.empty()) {
    cv::Mat left_desc, right_desc;
    RunTasks(runner, 2, [&](int j) {
      if (j == 0) m.orb_left->compute(left_grey, left_kp, left_desc);
      else m.orb_right->compute(right_grey, right_kp, right_desc);
    });
    std::vector<int> right_row(left_points.size(), -1);
    for (int k = 0; k < static_cast<int>(right_kp.size()); ++k) right_row[right_kp[k].class_id] = k;
    std::vector<char> has_left(left_points.size(), 0);
    for (int k = 0; k < static_cast<int>(left_kp.size()); ++k) {
      const int i = left_kp[k].class_id;
      has_left[i] = 1;
      if (right_row[i] < 0) {
        out[i].status = StereoReject::kOffImage;
        continue;
      }
      out[i].hamming = Hamming(left_desc.ptr<uint8_t>(k), right_desc.ptr<uint8_t>(right_row[i]));
      if (out[i].hamming <= o.max_hamming) out[i].status = StereoReject::kOk;
    }
    for (size_t i = 0; i < out.size(); ++i)
      if (out[i].status == StereoReject::kDescriptorDistance && !has_left[i])
        out[i].status = StereoReject::kOffImage;
  }
  return out;
}

}  // namespace cslam
