#include "system/map/reappearance.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "system/map/motion_agreement.h"

namespace cslam {

namespace {

// A body's reference point and size, robust to the few landmarks a window mislabelled (a
// static point 20 m off would drag a mean and an RMS radius by metres): the geometric median
// (Weiszfeld's iteration from the mean), which unlike a per-axis median does not depend on how
// the cluster frame is turned, and the median distance from it.
Eigen::Vector3d GeometricMedian(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (const auto& p : points) m += p;
  m /= static_cast<double>(points.size());
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double weights = 0;
    for (const auto& p : points) {
      const double w = 1.0 / std::max((p - m).norm(), 1e-9);
      sum += w * p;
      weights += w;
    }
    const Eigen::Vector3d next = sum / weights;
    const double step = (next - m).norm();
    m = next;
    if (step < 1e-6) break;
  }
  return m;
}

double MedianDistance(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& centre) {
  std::vector<double> d;
  d.reserve(points.size());
  for (const auto& p : points) d.push_back((p - centre).norm());
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// Least-squares line through positions over frames: the centre at the mean frame, the
// velocity per frame, the per-axis residual variance and the spread of the frames, which
// together give the variance of the line's value at any frame.
struct LineFit {
  double mean_frame = 0, sxx = 0, sigma2 = 0;
  int n = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d At(double f) const { return centre + velocity * (f - mean_frame); }
  double VelocityVariance() const { return sxx > 0 ? sigma2 / sxx : 0; }
  double VarianceAt(double f) const {
    return n > 0 ? sigma2 * (1.0 / n + (sxx > 0 ? (f - mean_frame) * (f - mean_frame) / sxx : 0))
                 : 0;
  }
};

LineFit FitLine(const std::vector<std::pair<int, Eigen::Vector3d>>& track) {
  LineFit fit;
  fit.n = static_cast<int>(track.size());
  if (fit.n == 0) return fit;
  for (const auto& [f, p] : track) {
    fit.mean_frame += f;
    fit.centre += p;
  }
  fit.mean_frame /= fit.n;
  fit.centre /= fit.n;
  Eigen::Vector3d sxp = Eigen::Vector3d::Zero();
  for (const auto& [f, p] : track) {
    fit.sxx += (f - fit.mean_frame) * (f - fit.mean_frame);
    sxp += (f - fit.mean_frame) * (p - fit.centre);
  }
  if (fit.sxx > 0) fit.velocity = sxp / fit.sxx;
  if (fit.n > 2) {
    double s = 0;
    for (const auto& [f, p] : track) s += (p - fit.At(f)).squaredNorm();
    fit.sigma2 = s / (3.0 * (fit.n - 2));
  }
  return fit;
}

// 99 % of a 3-D isotropic Gaussian lies within this many per-axis sigmas: sqrt(χ²₃(0.99)).
constexpr double kSigmas99In3d = 3.368;

}  // namespace

double Reappearance::Score() const {
  const double p = distance_m / allowed_m, v = speed_change_mps / allowed_speed_change_mps;
  return p * p + v * v;
}

// χ²₆(0.99) / χ²₃(0.99): the joint bound in units of the single ones.
bool Reappearance::Reachable() const {
  return compared > 0 && Precise() && Score() <= 16.812 / 11.345;
}

bool Reappearance::Precise() const {
  return uncertainty_m <= allowed_m - uncertainty_m &&
         uncertainty_mps <= allowed_speed_change_mps - uncertainty_mps;
}

bool WithinGap(const std::map<int, Pose>& world_from_a, const std::map<int, Pose>& world_from_b,
               const ReappearanceGate& gate) {
  if (world_from_a.empty() || world_from_b.empty() || !(gate.max_gap_s > 0) ||
      !(gate.frame_period_s > 0))
    return false;
  const int a_last = world_from_a.rbegin()->first, b_first = world_from_b.begin()->first;
  return b_first > a_last && (b_first - a_last) * gate.frame_period_s <= gate.max_gap_s;
}

Reappearance CompareAcrossGap(const std::map<int, Pose>& world_from_a,
                              const std::vector<Eigen::Vector3d>& points_in_a,
                              const std::map<int, Pose>& world_from_b,
                              const std::vector<Eigen::Vector3d>& points_in_b,
                              const ReappearanceGate& gate) {
  Reappearance result;
  // b is judged once it has been tracked for compare_frames: a young track's first poses
  // are too few to say where it is going, and a gate wide enough for them takes anything.
  if (!WithinGap(world_from_a, world_from_b, gate) || points_in_a.empty() ||
      points_in_b.empty() || world_from_b.size() < size_t(gate.compare_frames))
    return result;
  const int a_last = world_from_a.rbegin()->first, b_first = world_from_b.begin()->first;

  const Eigen::Vector3d ca = GeometricMedian(points_in_a), cb = GeometricMedian(points_in_b);
  std::vector<std::pair<int, Eigen::Vector3d>> a_track;
  for (auto it = world_from_a.rbegin();
       it != world_from_a.rend() && a_track.size() < size_t(gate.fit_frames); ++it)
    a_track.emplace_back(it->first, it->second * ca);
  if (a_track.size() < 3) return result;
  const LineFit a_fit = FitLine(a_track);
  // The body turns on at the mean rate over the fit, about the world axis it turned about.
  const Pose& a_end = world_from_a.rbegin()->second;
  const Pose& a_start = world_from_a.at(a_track.back().first);
  const Eigen::Vector3d turn_per_frame =
      LogSO3(a_end.linear() * a_start.linear().transpose()) / double(a_last - a_track.back().first);

  std::vector<std::pair<int, Eigen::Vector3d>> b_track;
  std::map<int, Pose> predicted, b_compared;
  for (auto it = world_from_b.begin(); b_track.size() < size_t(gate.compare_frames); ++it) {
    const int f = it->first;
    b_track.emplace_back(f, it->second * cb);
    Pose pose = Pose::Identity();
    pose.linear() = ExpSO3(turn_per_frame * double(f - a_last)) * a_end.linear();
    pose.translation() = a_fit.At(f) - pose.linear() * ca;
    predicted.emplace(f, pose);
    b_compared.emplace(f, it->second);
  }
  const LineFit b_fit = FitLine(b_track);

  // Both tracks' lines at b's first frame, each with the variance of its fit there.
  const double gap_s = (b_first - a_last) * gate.frame_period_s;
  result.gap_frames = b_first - a_last;
  result.compared = static_cast<int>(b_track.size());
  result.distance_m = (b_fit.At(b_first) - a_fit.At(b_first)).norm();
  result.uncertainty_m =
      kSigmas99In3d * std::sqrt(a_fit.VarianceAt(b_first) + b_fit.VarianceAt(b_first));
  result.allowed_m = MedianDistance(points_in_a, ca) + MedianDistance(points_in_b, cb) +
                     0.5 * gate.max_acceleration_mps2 * gap_s * gap_s + result.uncertainty_m;
  // Nor can its velocity have changed by more than the acceleration allows between the
  // middles of the two fits.
  const double between_s = (b_fit.mean_frame - a_fit.mean_frame) * gate.frame_period_s;
  result.speed_change_mps = (b_fit.velocity - a_fit.velocity).norm() / gate.frame_period_s;
  result.uncertainty_mps = kSigmas99In3d *
                           std::sqrt(a_fit.VelocityVariance() + b_fit.VelocityVariance()) /
                           gate.frame_period_s;
  result.allowed_speed_change_mps = gate.max_acceleration_mps2 * between_s + result.uncertainty_mps;
  // The prediction only says whether b can be a; where a's body is, b's own points say far
  // better than a prediction whose error grows with the square of the gap. The pieces are two
  // views of one body, so their centres coincide to within its extent: b's centre is put at
  // a's, turned as a's predicted turn says.
  if (result.Reachable()) {
    result.a_from_b = CompareMotions(predicted, b_compared, points_in_b).a_from_b;
    result.a_from_b.translation() = ca - result.a_from_b.linear() * cb;
  }
  return result;
}

}  // namespace cslam
