#include "backend/motion_distance.h"

#include <algorithm>
#include <cmath>

#include "core/options_reader.h"

namespace cslam {

void MotionDistanceOptions::Check() const {
  CheckOption(std::isfinite(alpha) && alpha >= 0, "motion_distance.alpha",
              "must be a finite number >= 0", alpha);
  CheckOption(min_co_observations >= 2, "motion_distance.min_co_observations",
              "must be >= 2 (a variance needs two frames)", min_co_observations);
  CheckOption(std::isfinite(min_variance_m2) && min_variance_m2 >= 1e-12 && min_variance_m2 <= 1.0,
              "motion_distance.min_variance_m2", "must be in [1e-12, 1] m^2", min_variance_m2);
}

void MotionDistanceOptions::Load(OptionsReader& reader) {
  reader.Read("alpha", &alpha);
  reader.Read("min_co_observations", &min_co_observations);
  reader.Read("use_uncertainty", &use_uncertainty);
  reader.Read("use_image_prior", &use_image_prior);
  reader.Read("mean_over_frames", &mean_over_frames);
  reader.Read("min_variance_m2", &min_variance_m2);
}

namespace {

// Everything the pair kernel reads about one (landmark, frame), flat for cache locality.
// Covariances are stored as their upper triangles (xx, xy, xz, yy, yz, zz).
struct Sample {
  int local = 0;
  double p[3];
  double c[6];
  double x[3];
  double xc[6];
};

// Running sums of one pair. The first term of Eq. 1 is Σ w (l − l*)² with l* = Σ w l / Σ w,
// evaluated in one pass as S2 − S1²/S0 on l − shift (shift = the first l) to avoid
// cancellation. Σ log σ is accumulated as a product folded into a log only when it leaves
// [1e-150, 1e150], i.e. about one log per several frames instead of one per frame.
struct Accumulator {
  int n = 0;
  double shift = 0, s0 = 0, s1 = 0, s2 = 0;
  double log_sum = 0, prod = 1;
  double prior = 0;
};

void UpperTriangle(const Eigen::Matrix3d& m, double* out) {
  out[0] = m(0, 0), out[1] = m(0, 1), out[2] = m(0, 2);
  out[3] = m(1, 1), out[4] = m(1, 2), out[5] = m(2, 2);
}

// vᵀ C v for symmetric C given by its upper triangle.
inline double QuadForm(const double* c, double v0, double v1, double v2) {
  return c[0] * v0 * v0 + c[3] * v1 * v1 + c[5] * v2 * v2 +
         2.0 * (c[1] * v0 * v1 + c[2] * v0 * v2 + c[4] * v1 * v2);
}

// vᵀ C⁻¹ v for symmetric positive definite C (adjugate formula); 0 when C is singular.
inline double InverseQuadForm(const double* c, double v0, double v1, double v2) {
  const double a00 = c[3] * c[5] - c[4] * c[4];
  const double a01 = c[2] * c[4] - c[1] * c[5];
  const double a02 = c[1] * c[4] - c[2] * c[3];
  const double a11 = c[0] * c[5] - c[2] * c[2];
  const double a12 = c[1] * c[2] - c[0] * c[4];
  const double a22 = c[0] * c[3] - c[1] * c[1];
  const double det = c[0] * a00 + c[1] * a01 + c[2] * a02;
  if (!(det > 0)) return 0.0;
  const double adj[6] = {a00, a01, a02, a11, a12, a22};
  return QuadForm(adj, v0, v1, v2) / det;
}

struct Kernel {
  bool use_uncertainty;
  bool use_prior;
  double min_variance;

  inline void operator()(const Sample& si, const Sample& sj, Accumulator& acc) const {
    const double l0 = si.p[0] - sj.p[0], l1 = si.p[1] - sj.p[1], l2 = si.p[2] - sj.p[2];
    const double n2 = l0 * l0 + l1 * l1 + l2 * l2;
    const double lt = std::sqrt(n2);
    double w = 1.0;
    if (use_uncertainty) {
      double c[6];
      for (int k = 0; k < 6; ++k) c[k] = si.c[k] + sj.c[k];
      // Eq. 2; for coincident points the Rayleigh quotient is undefined: use the mean
      // eigenvalue.
      double sigma = n2 > 1e-24 ? QuadForm(c, l0, l1, l2) / n2 : (c[0] + c[3] + c[5]) / 3.0;
      sigma = std::max(sigma, min_variance);
      w = 1.0 / sigma;
      acc.prod *= sigma;
      if (acc.prod < 1e-150 || acc.prod > 1e150) {
        acc.log_sum += std::log(acc.prod);
        acc.prod = 1.0;
      }
    }
    if (acc.n == 0) acc.shift = lt;
    const double dl = lt - acc.shift;
    acc.s0 += w;
    acc.s1 += w * dl;
    acc.s2 += w * dl * dl;
    ++acc.n;
    if (use_prior) {
      double c[6];
      for (int k = 0; k < 6; ++k) c[k] = si.xc[k] + sj.xc[k];
      const double m =
          InverseQuadForm(c, si.x[0] - sj.x[0], si.x[1] - sj.x[1], si.x[2] - sj.x[2]);
      acc.prior = std::max(acc.prior, m);
    }
  }
};

}  // namespace

SparseDistances ComputeMotionDistances(const TrackletTable& table, const PointTracks& tracks,
                                       FrameRange chunk, const MotionDistanceOptions& options) {
  SparseDistances out;
  const int num_frames = chunk.size();
  if (num_frames <= 0) return out;

  // Frame-major sample lists (ascending local id inside each frame) and, per item, where its
  // samples sit in them.
  std::vector<std::vector<Sample>> by_frame(num_frames);
  std::vector<std::vector<std::pair<int, int>>> slots;  // [local] → (frame offset, index)
  for (int l : table.LandmarksIn(chunk, options.min_co_observations)) {
    if (l >= static_cast<int>(tracks.size())) continue;
    const auto& samples = tracks[l].samples;
    auto lo = std::lower_bound(samples.begin(), samples.end(), chunk.begin,
                               [](const PointSample& s, int f) { return s.frame < f; });
    auto hi = std::lower_bound(lo, samples.end(), chunk.end,
                               [](const PointSample& s, int f) { return s.frame < f; });
    if (hi - lo < options.min_co_observations) continue;
    const auto obs = table.ObservationsOf(l, chunk);
    const int local = out.size();
    std::vector<std::pair<int, int>> my_slots;
    size_t k = 0;
    for (auto it = lo; it != hi; ++it) {
      while (k < obs.size() && obs[k].frame < it->frame) ++k;
      if (k == obs.size() || obs[k].frame != it->frame) continue;  // no keypoint: skip frame
      Sample s;
      s.local = local;
      for (int a = 0; a < 3; ++a) s.p[a] = it->point(a), s.x[a] = obs[k].x(a);
      UpperTriangle(it->cov, s.c);
      UpperTriangle(obs[k].cov, s.xc);
      const int f = it->frame - chunk.begin;
      my_slots.emplace_back(f, static_cast<int>(by_frame[f].size()));
      by_frame[f].push_back(s);
    }
    if (static_cast<int>(my_slots.size()) < options.min_co_observations) {
      for (const auto& [f, idx] : my_slots) by_frame[f].pop_back();
      continue;
    }
    out.landmarks.push_back(l);
    slots.push_back(std::move(my_slots));
  }

  const int n = out.size();
  const Kernel kernel{options.use_uncertainty, options.use_image_prior, options.min_variance_m2};
  std::vector<Accumulator> acc(n);
  std::vector<int> touched;
  touched.reserve(n);
  for (int i = 0; i < n; ++i) {
    for (const auto& [f, idx] : slots[i]) {
      const auto& frame = by_frame[f];
      const Sample& si = frame[idx];
      for (size_t q = idx + 1; q < frame.size(); ++q) {
        const Sample& sj = frame[q];
        Accumulator& a = acc[sj.local];
        if (a.n == 0) touched.push_back(sj.local);
        kernel(si, sj, a);
      }
    }
    std::sort(touched.begin(), touched.end());
    for (int j : touched) {
      Accumulator& a = acc[j];
      if (a.n >= options.min_co_observations) {
        double first = std::max(0.0, a.s2 - a.s1 * a.s1 / a.s0);
        if (options.use_uncertainty) first += a.log_sum + std::log(a.prod);
        if (options.mean_over_frames) first /= a.n;
        out.entries.push_back({i, j, first + options.alpha * a.prior});
      }
      a = Accumulator();
    }
    touched.clear();
  }
  return out;
}

}  // namespace cslam
