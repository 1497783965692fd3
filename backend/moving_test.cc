#include "backend/moving_test.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/errors.h"

namespace cslam {

void MovingTestOptions::Check() const {
  CheckOption(false_alarm > 0 && false_alarm < 1, "false_alarm",
              "must be a probability in (0, 1)", false_alarm);
  CheckOption(std::isfinite(sample_gate_chi2) && sample_gate_chi2 > 0,
              "sample_gate_chi2", "must be a chi-square > 0", sample_gate_chi2);
  CheckOption(std::isfinite(max_disparity_offset_px) && max_disparity_offset_px >= 0,
              "max_disparity_offset_px", "must be >= 0 px (0: off)",
              max_disparity_offset_px);
  CheckOption(std::isfinite(model_error_px) && model_error_px >= 0, "model_error_px",
              "must be >= 0 px (0: the keypoint covariances alone)", model_error_px);
}

void MovingTestOptions::Load(OptionsReader& reader) {
  reader.Read("false_alarm", &false_alarm);
  reader.Read("sample_gate_chi2", &sample_gate_chi2);
  reader.Read("max_disparity_offset_px", &max_disparity_offset_px);
  reader.Read("model_error_px", &model_error_px);
}

double ChiSquareUpperQuantile(double dof, double p) {
  CSLAM_CHECK(dof > 0 && p > 0 && p < 1, "chi-square quantile needs dof > 0 and 0 < p < 1");
  // z with P(Z > z) = p, by bisection on the normal tail 0.5 erfc(z / √2) (decreasing in z).
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  const double z = 0.5 * (lo + hi);
  const double a = 2.0 / (9.0 * dof);
  const double c = 1.0 - a + z * std::sqrt(a);
  return dof * std::max(c, 0.0) * c * c;
}

namespace {

// One track's samples mapped by a model: y = T X(δ) with X(δ) = X + δ g, and their weights.
struct Mapped {
  std::vector<Eigen::Vector3d> y, h;  // h = R g: how y moves per px of disparity offset
  std::vector<Eigen::Matrix3d> w;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero(), bh = Eigen::Vector3d::Zero();
};

// The sample's covariance plus σ² J Jᵀ, J = ∂X/∂(uL, v, uR) rebuilt from the point, its
// disparity and metres per pixel (fx = fy).
Eigen::Matrix3d Floored(const PointSample& s, double sigma_px) {
  if (!(sigma_px > 0) || !(s.disparity_px > 0) || !(s.metres_per_px > 0)) return s.cov;
  const Eigen::Vector3d along = s.point / s.disparity_px;
  Eigen::Matrix3d j;
  j.col(0) = s.metres_per_px * Eigen::Vector3d::UnitX() - along;
  j.col(1) = s.metres_per_px * Eigen::Vector3d::UnitY();
  j.col(2) = along;
  return s.cov + sigma_px * sigma_px * j * j.transpose();
}

void MapTrack(const PointTrack& track, const ModelPose& model,
              const std::function<bool(int)>& covered, double offset_px, double sigma_px,
              Mapped* m) {
  m->y.clear();
  m->h.clear();
  m->w.clear();
  m->a.setZero();
  m->b.setZero();
  m->bh.setZero();
  for (const PointSample& s : track.samples) {
    if (s.clipped || !covered(s.frame)) continue;
    const Pose* p = model(s.frame);
    if (!p) continue;
    const Eigen::Matrix3d r = p->linear();
    // A disparity read δ px too large places the point at X (1 − δ / d): dX/dδ = −X / d.
    const Eigen::Vector3d g =
        s.disparity_px > 0 ? Eigen::Vector3d(-s.point / s.disparity_px) : Eigen::Vector3d::Zero();
    m->y.push_back(*p * (s.point + offset_px * g));
    m->h.push_back(r * g);
    m->w.push_back(r * Floored(s, sigma_px).inverse() * r.transpose());
    m->a += m->w.back();
    m->b += m->w.back() * m->y.back();
    m->bh += m->w.back() * m->h.back();
  }
}

}  // namespace

double CappedTrackChi2(const PointTrack& track, const ModelPose& model,
                       const std::function<bool(int)>& covered, double gate_chi2, int* used,
                       double offset_px, double model_error_px) {
  thread_local Mapped m;
  MapTrack(track, model, covered, offset_px, model_error_px, &m);
  const int n = static_cast<int>(m.y.size());
  if (used) *used = n;
  if (n < 2) return 0.0;
  // The mean of the samples within the gate of the all-sample mean: a jump does not drag it.
  Eigen::Vector3d mean = m.a.ldlt().solve(m.b);
  Eigen::Matrix3d a_in = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b_in = Eigen::Vector3d::Zero();
  int inliers = 0;
  for (int k = 0; k < n; ++k) {
    if ((m.y[k] - mean).dot(m.w[k] * (m.y[k] - mean)) > gate_chi2) continue;
    a_in += m.w[k];
    b_in += m.w[k] * m.y[k];
    ++inliers;
  }
  if (inliers >= 2) mean = a_in.ldlt().solve(b_in);
  double chi2 = 0.0;
  for (int k = 0; k < n; ++k)
    chi2 += std::min((m.y[k] - mean).dot(m.w[k] * (m.y[k] - mean)), gate_chi2);
  return std::isfinite(chi2) ? chi2 : gate_chi2 * n;
}

double FitDisparityOffset(const std::vector<const PointTrack*>& tracks, const ModelPose& model,
                          const std::function<bool(int)>& covered, double gate_chi2,
                          double max_offset_px, double model_error_px) {
  // χ²(δ) is quadratic: per track, residuals r = y − ȳ and directions e = h − h̄ about the
  // weighted means; δ* = −Σ eᵀW r / Σ eᵀW e over the samples within the gate at δ = 0.
  thread_local Mapped m;
  double num = 0.0, den = 0.0;
  for (const PointTrack* track : tracks) {
    if (!track) continue;
    MapTrack(*track, model, covered, 0.0, model_error_px, &m);
    const int n = static_cast<int>(m.y.size());
    if (n < 2) continue;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(m.a);
    const Eigen::Vector3d mean = ldlt.solve(m.b), mean_h = ldlt.solve(m.bh);
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d r = m.y[k] - mean, e = m.h[k] - mean_h;
      if (r.dot(m.w[k] * r) > gate_chi2) continue;
      num += e.dot(m.w[k] * r);
      den += e.dot(m.w[k] * e);
    }
  }
  if (!(den > 0) || !std::isfinite(num)) return 0.0;
  return std::clamp(-num / den, -max_offset_px, max_offset_px);
}

MovingTestResult TestMoving(const std::vector<const PointTrack*>& tracks,
                            const ModelPose& static_model, const ModelPose& own_model,
                            const MovingTestOptions& options) {
  MovingTestResult r;
  const auto both = [&](int frame) { return static_model(frame) && own_model(frame); };
  if (options.max_disparity_offset_px > 0) {
    r.offset_static_px = FitDisparityOffset(tracks, static_model, both, options.sample_gate_chi2,
                                            options.max_disparity_offset_px,
                                            options.model_error_px);
    r.offset_own_px = FitDisparityOffset(tracks, own_model, both, options.sample_gate_chi2,
                                         options.max_disparity_offset_px, options.model_error_px);
  }
  std::map<int, int> per_frame;  // frame → landmarks with a sample there
  for (const PointTrack* track : tracks) {
    if (!track) continue;
    int used_static = 0, used_own = 0;
    const double s = CappedTrackChi2(*track, static_model, both, options.sample_gate_chi2,
                                     &used_static, r.offset_static_px, options.model_error_px);
    const double o = CappedTrackChi2(*track, own_model, both, options.sample_gate_chi2, &used_own,
                                     r.offset_own_px, options.model_error_px);
    if (used_static < 2) continue;
    r.chi2_static += s;
    r.chi2_own += o;
    ++r.landmarks;
    for (const PointSample& sample : track->samples)
      if (both(sample.frame)) ++per_frame[sample.frame];
  }
  r.frames = static_cast<int>(per_frame.size());
  // One landmark in a frame fixes 3 of the pose's 6 unknowns, two fix 5, three or more all 6;
  // the cluster frame's own placement (6) is absorbed by the landmarks' positions.
  int dof = 0;
  for (const auto& [frame, count] : per_frame) dof += count >= 3 ? 6 : count == 2 ? 5 : 3;
  r.dof = std::max(dof - 6, 0);
  if (r.dof == 0) return r;
  r.threshold = ChiSquareUpperQuantile(r.dof, options.false_alarm);
  r.moving = r.Statistic() > r.threshold;
  return r;
}

}  // namespace cslam

