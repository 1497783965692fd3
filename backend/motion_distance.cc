#include "backend/motion_distance.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/options_reader.h"

namespace cslam {

void MotionDistanceOptions::Check() const {
  CheckOption(std::isfinite(alpha) && alpha >= 0, "alpha",
              "must be a finite number >= 0", alpha);
  CheckOption(min_co_observations >= 2, "min_co_observations",
              "must be >= 2 (a variance needs two frames)", min_co_observations);
  CheckOption(std::isfinite(min_variance_m2) && min_variance_m2 >= 1e-12 && min_variance_m2 <= 1.0,
              "min_variance_m2", "must be in [1e-12, 1] m^2", min_variance_m2);
  CheckOption(std::isfinite(max_extent_m) && max_extent_m >= 0, "max_extent_m",
              "must be >= 0 m (0 = off)", max_extent_m);
}

void MotionDistanceOptions::Load(OptionsReader& reader) {
  reader.Read("alpha", &alpha);
  reader.Read("min_co_observations", &min_co_observations);
  reader.Read("use_uncertainty", &use_uncertainty);
  reader.Read("use_image_prior", &use_image_prior);
  reader.Read("mean_over_frames", &mean_over_frames);
  reader.Read("min_variance_m2", &min_variance_m2);
  reader.Read("max_extent_m", &max_extent_m);
}

namespace {

// Per-chunk storage of every item's samples over its frame span [first, first + length):
// structure of arrays in float, one row per field, so a pair's co-observed frames are two
// aligned contiguous segments and the pair kernel is one branch-free SIMD loop. Frames inside
// a span without a sample have mask 0 and harmless filler values (point 0, identity
// covariances). Float is enough: the first term is evaluated in two
// passes (l* first, then Σ w (l − l*)²), so no large sums cancel; results agree with a
// double-precision evaluation to ~1e-6 relative.
enum Field : int {
  kPx, kPy, kPz,
  kC00, kC01, kC02, kC11, kC12, kC22,
  kU, kV, kUr,
  kX00, kX01, kX02, kX11, kX12, kX22,
  kMask,
  kNumFields
};

struct Span {
  int first = 0;   // chunk-relative frame
  int length = 0;
  int offset = 0;  // column of `first` in the storage
};

constexpr int kBlock = 64;  // 64 mantissas in [1, 2) multiply to < 2^64: no float overflow
constexpr double kLn2 = 0.69314718055994530942;

// Sums of pass 1 over one block of frames.
struct BlockSums {
  float s0 = 0, s1 = 0, count = 0, mant = 1, prior = 0;
  int exps = 0;
};

// Pass 1 over frames [b0, b1) of a pair, branch-free so it vectorises; the switches are
// template parameters so each variant is its own straight loop.
template <bool kUseU, bool kUsePrior, bool kIsotropic>
void PairBlock(const float* const* A, const float* const* B, int b0, int b1, float floor,
               float* __restrict lt, float* __restrict w, float* __restrict sig,
               BlockSums* out) {
  [[maybe_unused]] const float* __restrict aMask = A[kMask];
  [[maybe_unused]] const float* __restrict bMask = B[kMask];
  [[maybe_unused]] const float* __restrict aPx = A[kPx];
  [[maybe_unused]] const float* __restrict bPx = B[kPx];
  [[maybe_unused]] const float* __restrict aPy = A[kPy];
  [[maybe_unused]] const float* __restrict bPy = B[kPy];
  [[maybe_unused]] const float* __restrict aPz = A[kPz];
  [[maybe_unused]] const float* __restrict bPz = B[kPz];
  [[maybe_unused]] const float* __restrict aC00 = A[kC00];
  [[maybe_unused]] const float* __restrict bC00 = B[kC00];
  [[maybe_unused]] const float* __restrict aC01 = A[kC01];
  [[maybe_unused]] const float* __restrict bC01 = B[kC01];
  [[maybe_unused]] const float* __restrict aC02 = A[kC02];
  [[maybe_unused]] const float* __restrict bC02 = B[kC02];
  [[maybe_unused]] const float* __restrict aC11 = A[kC11];
  [[maybe_unused]] const float* __restrict bC11 = B[kC11];
  [[maybe_unused]] const float* __restrict aC12 = A[kC12];
  [[maybe_unused]] const float* __restrict bC12 = B[kC12];
  [[maybe_unused]] const float* __restrict aC22 = A[kC22];
  [[maybe_unused]] const float* __restrict bC22 = B[kC22];
  [[maybe_unused]] const float* __restrict aU = A[kU];
  [[maybe_unused]] const float* __restrict bU = B[kU];
  [[maybe_unused]] const float* __restrict aV = A[kV];
  [[maybe_unused]] const float* __restrict bV = B[kV];
  [[maybe_unused]] const float* __restrict aUr = A[kUr];
  [[maybe_unused]] const float* __restrict bUr = B[kUr];
  [[maybe_unused]] const float* __restrict aX00 = A[kX00];
  [[maybe_unused]] const float* __restrict bX00 = B[kX00];
  [[maybe_unused]] const float* __restrict aX01 = A[kX01];
  [[maybe_unused]] const float* __restrict bX01 = B[kX01];
  [[maybe_unused]] const float* __restrict aX02 = A[kX02];
  [[maybe_unused]] const float* __restrict bX02 = B[kX02];
  [[maybe_unused]] const float* __restrict aX11 = A[kX11];
  [[maybe_unused]] const float* __restrict bX11 = B[kX11];
  [[maybe_unused]] const float* __restrict aX12 = A[kX12];
  [[maybe_unused]] const float* __restrict bX12 = B[kX12];
  [[maybe_unused]] const float* __restrict aX22 = A[kX22];
  [[maybe_unused]] const float* __restrict bX22 = B[kX22];
  float bs0 = 0, bs1 = 0, bcount = 0, mant = 1, bprior = 0;
  int exps = 0;
#pragma omp simd reduction(+ : bs0, bs1, bcount) reduction(max : bprior)
  for (int k = b0; k < b1; ++k) {
    const float m = aMask[k] * bMask[k];
    const float l0 = aPx[k] - bPx[k], l1 = aPy[k] - bPy[k],
                l2 = aPz[k] - bPz[k];
    const float n2 = l0 * l0 + l1 * l1 + l2 * l2;
    const float len_k = std::sqrt(n2);
    float wk = m;
    if constexpr (kUseU) {
      // Eq. 2: σ = lᵀ(Σi + Σj)l / lᵀl; coincident points fall to the floor.
      const float q = (aC00[k] + bC00[k]) * l0 * l0 +
                      (aC11[k] + bC11[k]) * l1 * l1 +
                      (aC22[k] + bC22[k]) * l2 * l2 +
                      2.0f * ((aC01[k] + bC01[k]) * l0 * l1 +
                              (aC02[k] + bC02[k]) * l0 * l2 +
                              (aC12[k] + bC12[k]) * l1 * l2);
      const float n2_safe = n2 > 1e-24f ? n2 : 1e-24f;
      const float sigma_raw = q / n2_safe;
      const float sigma = sigma_raw > floor ? sigma_raw : floor;
      wk = m / sigma;
      // log σ on co-observed frames only (σ_eff = 1 elsewhere), split as 2^e · mantissa.
      sig[k] = m > 0.5f ? sigma : 1.0f;  // not 1 + m(σ − 1): that cancels in float
    }
    lt[k] = len_k;
    w[k] = wk;
    bs0 += wk;
    bs1 += wk * len_k;
    bcount += m;
    if constexpr (kUsePrior) {
      const float du = aU[k] - bU[k], dv = aV[k] - bV[k],
                  dr = aUr[k] - bUr[k];
      float mahal;
      if constexpr (kIsotropic) {
        // Every keypoint covariance is s·I: ΔxᵀC⁻¹Δx = |Δx|² / (si + sj).
        mahal = (du * du + dv * dv + dr * dr) / (aX00[k] + bX00[k]);
      } else {
        // ΔxᵀC⁻¹Δx, C = Σxi + Σxj, by the adjugate of the symmetric C.
        const float c00 = aX00[k] + bX00[k], c01 = aX01[k] + bX01[k],
                    c02 = aX02[k] + bX02[k], c11 = aX11[k] + bX11[k],
                    c12 = aX12[k] + bX12[k], c22 = aX22[k] + bX22[k];
        const float a00 = c11 * c22 - c12 * c12, a01 = c02 * c12 - c01 * c22,
                    a02 = c01 * c12 - c02 * c11, a11 = c00 * c22 - c02 * c02,
                    a12 = c01 * c02 - c00 * c12, a22 = c00 * c11 - c01 * c01;
        const float det_raw = c00 * a00 + c01 * a01 + c02 * a02;
        const float det = det_raw > 1e-30f ? det_raw : 1e-30f;
        mahal = (a00 * du * du + a11 * dv * dv + a22 * dr * dr +
                 2.0f * (a01 * du * dv + a02 * du * dr + a12 * dv * dr)) /
                det;
      }
      const float pm = m * mahal;  // no std::max: a reference defeats the vectoriser
      bprior = bprior > pm ? bprior : pm;
    }
  }
  if constexpr (kUseU) {
    // Σ log σ = ln 2 · Σ exponents + log Π mantissas (each in [1, 2), so a block of 64 stays
    // below 2^64): integer work per frame and one log per block instead of one per frame.
    for (int k = b0; k < b1; ++k) {
      const uint32_t bits = std::bit_cast<uint32_t>(sig[k]);
      exps += static_cast<int>(bits >> 23) - 127;
      mant *= std::bit_cast<float>((bits & 0x007fffffu) | 0x3f800000u);
    }
  }
  out->s0 = bs0, out->s1 = bs1, out->count = bcount, out->mant = mant, out->prior = bprior;
  out->exps = exps;
}

using PairKernel = void (*)(const float* const*, const float* const*, int, int, float, float*,
                            float*, float*, BlockSums*);

template <bool kUseU, bool kUsePrior>
PairKernel SelectIsotropic(bool iso) {
  return iso ? &PairBlock<kUseU, kUsePrior, true> : &PairBlock<kUseU, kUsePrior, false>;
}

PairKernel SelectKernel(bool use_u, bool use_prior, bool iso) {
  if (use_u) return use_prior ? SelectIsotropic<true, true>(iso) : SelectIsotropic<true, false>(iso);
  return use_prior ? SelectIsotropic<false, true>(iso) : SelectIsotropic<false, false>(iso);
}

void UpperTriangle(const Eigen::Matrix3d& m, float* const* rows, int col) {
  rows[0][col] = static_cast<float>(m(0, 0)), rows[1][col] = static_cast<float>(m(0, 1));
  rows[2][col] = static_cast<float>(m(0, 2)), rows[3][col] = static_cast<float>(m(1, 1));
  rows[4][col] = static_cast<float>(m(1, 2)), rows[5][col] = static_cast<float>(m(2, 2));
}

}  // namespace

SparseDistances ComputeMotionDistances(const TrackletTable& table, const PointTracks& tracks,
                                       FrameRange chunk, const MotionDistanceOptions& options) {
  SparseDistances out;
  if (chunk.size() <= 0) return out;
  const int min_co = options.min_co_observations;

  // 1. Items and their spans: samples that have both a 3-D point and a keypoint.
  struct Pending {
    int landmark;
    std::vector<std::pair<const PointSample*, const StereoObservation*>> samples;
  };
  std::vector<Pending> items;
  for (int l : table.LandmarksIn(chunk, min_co)) {
    if (l >= static_cast<int>(tracks.size())) continue;
    const auto& samples = tracks[l].samples;
    auto lo = std::lower_bound(samples.begin(), samples.end(), chunk.begin,
                               [](const PointSample& s, int f) { return s.frame < f; });
    const auto obs = table.ObservationsOf(l, chunk);
    Pending p{l, {}};
    size_t k = 0;
    for (auto it = lo; it != samples.end() && it->frame < chunk.end; ++it) {
      while (k < obs.size() && obs[k].frame < it->frame) ++k;
      if (k < obs.size() && obs[k].frame == it->frame) p.samples.emplace_back(&*it, &obs[k]);
    }
    if (static_cast<int>(p.samples.size()) >= min_co) items.push_back(std::move(p));
  }
  const int n = static_cast<int>(items.size());
  std::vector<Span> spans(n);
  int columns = 0;
  for (int i = 0; i < n; ++i) {
    out.landmarks.push_back(items[i].landmark);
    spans[i].first = items[i].samples.front().first->frame - chunk.begin;
    spans[i].length = items[i].samples.back().first->frame - chunk.begin - spans[i].first + 1;
    spans[i].offset = columns;
    columns += spans[i].length;
  }

  // 2. Structure-of-arrays storage, filler first.
  std::vector<float> storage(static_cast<size_t>(kNumFields) * columns, 0.0f);
  float* rows[kNumFields];
  for (int f = 0; f < kNumFields; ++f) rows[f] = storage.data() + static_cast<size_t>(f) * columns;
  for (int f : {kC00, kC11, kC22, kX00, kX11, kX22}) std::fill(rows[f], rows[f] + columns, 1.0f);
  bool isotropic_keypoints = true;  // then the prior needs no 3×3 inverse
  for (int i = 0; i < n; ++i) {
    for (const auto& [ps, ob] : items[i].samples) {
      const int col = spans[i].offset + (ps->frame - chunk.begin - spans[i].first);
      for (int a = 0; a < 3; ++a) {
        rows[kPx + a][col] = static_cast<float>(ps->point(a));
        rows[kU + a][col] = static_cast<float>(ob->x(a));
      }
      UpperTriangle(ps->cov, rows + kC00, col);
      UpperTriangle(ob->cov, rows + kX00, col);
      const Eigen::Matrix3d& xc = ob->cov;
      isotropic_keypoints = isotropic_keypoints && xc(0, 1) == 0 && xc(0, 2) == 0 &&
                            xc(1, 2) == 0 && xc(1, 0) == 0 && xc(2, 0) == 0 && xc(2, 1) == 0 &&
                            xc(1, 1) == xc(0, 0) && xc(2, 2) == xc(0, 0);
      rows[kMask][col] = 1.0f;
    }
  }
  items.clear();

  // 3. Candidate pairs: spans overlapping by >= min_co frames, found by a sweep over items
  // sorted by first frame (never all n² pairs of the chunk).
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return spans[a].first != spans[b].first ? spans[a].first < spans[b].first : a < b;
  });

  const bool use_u = options.use_uncertainty, use_prior = options.use_image_prior;
  const float floor = static_cast<float>(options.min_variance_m2);
  std::vector<float> lt_buf(chunk.size()), w_buf(chunk.size()), sig_buf(chunk.size());
  const PairKernel kernel = SelectKernel(use_u, use_prior, isotropic_keypoints);
  for (int oi = 0; oi < n; ++oi) {
    const int i = order[oi];
    const Span& si = spans[i];
    const int end_i = si.first + si.length;
    for (int oj = oi + 1; oj < n; ++oj) {
      const int j = order[oj];
      const Span& sj = spans[j];
      if (sj.first > end_i - min_co) break;  // later items start even later
      const int lo = sj.first, hi = std::min(end_i, sj.first + sj.length);
      const int len = hi - lo;
      if (len < min_co) continue;
      const int ci = si.offset + (lo - si.first), cj = sj.offset + (lo - sj.first);
      // Pass 1, fused and vectorised (omp simd; -fopenmp-simd needs no OpenMP runtime), in
      // blocks of kBlock frames so that the product of the variances' mantissas (each in
      // [1, 2)) fits a float: Σ log σ = ln 2 · Σ exponents + log Π mantissas, one log per block.
      double s0 = 0, s1 = 0, log_sum = 0, count = 0;
      float prior = 0.0f;
      const float* Ai[kNumFields];
      const float* Bj[kNumFields];
      for (int f = 0; f < kNumFields; ++f) Ai[f] = rows[f] + ci, Bj[f] = rows[f] + cj;
      float* lt = lt_buf.data();
      float* w = w_buf.data();
      for (int b0 = 0; b0 < len; b0 += kBlock) {
        const int b1 = std::min(len, b0 + kBlock);
        BlockSums bsum;
        kernel(Ai, Bj, b0, b1, floor, lt, w, sig_buf.data(), &bsum);
        const float bs0 = bsum.s0, bs1 = bsum.s1, bcount = bsum.count, mant = bsum.mant,
                    bprior = bsum.prior;
        const int exps = bsum.exps;
        s0 += bs0;
        s1 += bs1;
        count += bcount;
        prior = std::max(prior, bprior);
        if (use_u) log_sum += std::log(static_cast<double>(mant)) + kLn2 * exps;
      }
      if (count < min_co - 0.5) continue;
      // Pass 2: Σ w (l − l*)² about the weighted mean.
      const float l_star = static_cast<float>(s1 / s0);
      float spread = 0.0f;
#pragma omp simd reduction(+ : spread)
      for (int k = 0; k < len; ++k) spread += w[k] * (lt[k] - l_star) * (lt[k] - l_star);
      double first = spread + log_sum;
      if (options.mean_over_frames) first /= count;
      // Two points of one small body cannot be farther apart than its extent: l* beyond it,
      // weighed by l*'s information Σ w (w = 1/σ), is evidence of two bodies however alike
      // their motions are over a short chunk (two cars in one lane at one speed).
      double extent = 0.0;
      if (options.max_extent_m > 0) {
        const double beyond = std::max(0.0, s1 / s0 - options.max_extent_m);
        extent = beyond * beyond * s0;
      }
      out.entries.push_back(
          {std::min(i, j), std::max(i, j), first + options.alpha * double(prior) + extent});
    }
  }
  // The list grew by doubling; up to half of it is slack that the clustering would carry
  // through its own peak (a cold window holds ~1 M entries).
  out.entries.shrink_to_fit();
  return out;
}

}  // namespace cslam
