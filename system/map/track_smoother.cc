#include "system/map/track_smoother.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace cslam {

void TrackSmootherOptions::Check() const {
  CheckOption(std::isfinite(acceleration_mps2) && acceleration_mps2 > 0, "acceleration_mps2",
              "must be positive (m/s² of white acceleration a body can take)", acceleration_mps2);
  CheckOption(std::isfinite(angular_rate_sigma_radps) && angular_rate_sigma_radps > 0,
              "angular_rate_sigma_radps", "must be positive (rad/s)", angular_rate_sigma_radps);
  CheckOption(std::isfinite(angular_rate_time_s) && angular_rate_time_s > 0,
              "angular_rate_time_s", "must be positive (s)", angular_rate_time_s);
  CheckOption(std::isfinite(gate_chi2) && gate_chi2 > 0, "gate_chi2",
              "must be positive (squared Mahalanobis distance, 3 dof)", gate_chi2);
  CheckOption(passes >= 0 && passes <= 50, "passes", "must be in [0, 50]", passes);
  CheckOption(std::isfinite(max_gap_s) && max_gap_s >= 0, "max_gap_s",
              "must be >= 0 (seconds a body is predicted without measurements)", max_gap_s);
}

void TrackSmootherOptions::Load(OptionsReader& r) {
  r.Read("acceleration_mps2", &acceleration_mps2);
  r.Read("angular_rate_sigma_radps", &angular_rate_sigma_radps);
  r.Read("angular_rate_time_s", &angular_rate_time_s);
  r.Read("gate_chi2", &gate_chi2);
  r.Read("passes", &passes);
  r.Read("max_gap_s", &max_gap_s);
}

namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// The two spaces a track lives in: positions, and rotations perturbed on the left (world).
struct PositionSpace {
  using X = Eigen::Vector3d;
  static X Plus(const X& x, const Eigen::Vector3d& d) { return x + d; }
  static Eigen::Vector3d Minus(const X& a, const X& b) { return a - b; }
  static constexpr double kInitialSigma = 1e3;          // m: the first measurement decides
  static constexpr double kInitialVelocitySigma = 30;  // m/s: any road speed
};
struct RotationSpace {
  using X = Eigen::Matrix3d;
  static X Plus(const X& x, const Eigen::Vector3d& d) { return ExpSO3(d) * x; }
  static Eigen::Vector3d Minus(const X& a, const X& b) { return LogSO3(a * b.transpose()); }
  static constexpr double kInitialSigma = M_PI;
  static constexpr double kInitialVelocitySigma = 1.0;  // rad/s: a tight turn's yaw rate
};

// One stretch of consecutive frames; measured[k] < 0 where frame k has no measurement.
struct Stretch {
  std::vector<int> frames;
  std::vector<double> times;
  std::vector<int> measured;  // index into the measurements, or -1
};

template <typename S>
struct Smoothed {
  std::vector<typename S::X> x;
  std::vector<Eigen::Vector3d> v;
  std::vector<Matrix6d> P;
};

// The motion model: velocity kept (tau = inf) or decaying to zero with time constant tau.
struct Model {
  double q = 1;                // spectral density of the velocity's driving noise
  double tau = INFINITY;       // s
};

Matrix6d Transition(double dt, const Model& model) {
  Matrix6d F = Matrix6d::Identity();
  F.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  F.bottomRightCorner<3, 3>() = std::exp(-dt / model.tau) * Eigen::Matrix3d::Identity();
  return F;
}

// White acceleration of spectral density q over dt (the discretised constant-velocity model).
Matrix6d ProcessNoise(double dt, double q) {
  Matrix6d Q = Matrix6d::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Q.topLeftCorner<3, 3>() = q * dt * dt * dt / 3 * I;
  Q.topRightCorner<3, 3>() = q * dt * dt / 2 * I;
  Q.bottomLeftCorner<3, 3>() = q * dt * dt / 2 * I;
  Q.bottomRightCorner<3, 3>() = q * dt * I;
  return Q;
}

// Kalman filter forward, Rauch–Tung–Striebel backward over one stretch. z[k] / cov[k] are the
// measurement at frame k (cov already divided by its weight); use[k] false skips it.
template <typename S>
Smoothed<S> FilterAndSmooth(const Stretch& s, const std::vector<typename S::X>& z,
                            const std::vector<Eigen::Matrix3d>& cov, const std::vector<bool>& use,
                            const Model& model) {
  const size_t n = s.frames.size();
  std::vector<typename S::X> x_pred(n), x_filt(n);
  std::vector<Eigen::Vector3d> v_pred(n), v_filt(n);
  std::vector<Matrix6d> P_pred(n), P_filt(n);
  for (size_t k = 0; k < n; ++k) {
    if (k == 0) {
      x_pred[0] = z[0];  // a stretch starts at a measured frame
      v_pred[0].setZero();
      P_pred[0].setZero();
      P_pred[0].topLeftCorner<3, 3>() = std::pow(S::kInitialSigma, 2) * Eigen::Matrix3d::Identity();
      P_pred[0].bottomRightCorner<3, 3>() =
          std::pow(S::kInitialVelocitySigma, 2) * Eigen::Matrix3d::Identity();
    } else {
      const double dt = s.times[k] - s.times[k - 1];
      const Matrix6d F = Transition(dt, model);
      x_pred[k] = S::Plus(x_filt[k - 1], v_filt[k - 1] * dt);
      v_pred[k] = F.bottomRightCorner<3, 3>() * v_filt[k - 1];
      P_pred[k] = F * P_filt[k - 1] * F.transpose() + ProcessNoise(dt, model.q);
    }
    x_filt[k] = x_pred[k];
    v_filt[k] = v_pred[k];
    P_filt[k] = P_pred[k];
    if (!use[k]) continue;
    const Eigen::Vector3d y = S::Minus(z[k], x_pred[k]);
    const Eigen::Matrix3d innovation = P_pred[k].topLeftCorner<3, 3>() + cov[k];
    const Eigen::Matrix<double, 6, 3> K =
        P_pred[k].leftCols<3>() * innovation.ldlt().solve(Eigen::Matrix3d::Identity());
    const Vector6d d = K * y;
    x_filt[k] = S::Plus(x_pred[k], d.head<3>());
    v_filt[k] = v_pred[k] + d.tail<3>();
    Matrix6d IKH = Matrix6d::Identity();
    IKH.leftCols<3>() -= K;
    P_filt[k] = IKH * P_pred[k] * IKH.transpose() + K * cov[k] * K.transpose();  // Joseph form
  }
  Smoothed<S> out{x_filt, v_filt, P_filt};
  for (size_t k = n - 1; k-- > 0;) {
    const Matrix6d F = Transition(s.times[k + 1] - s.times[k], model);
    const Matrix6d G =
        P_filt[k] * F.transpose() * P_pred[k + 1].ldlt().solve(Matrix6d::Identity());
    Vector6d d;
    d.head<3>() = S::Minus(out.x[k + 1], x_pred[k + 1]);
    d.tail<3>() = out.v[k + 1] - v_pred[k + 1];
    const Vector6d delta = G * d;
    out.x[k] = S::Plus(x_filt[k], delta.head<3>());
    out.v[k] = v_filt[k] + delta.tail<3>();
    out.P[k] = P_filt[k] + G * (out.P[k + 1] - P_pred[k + 1]) * G.transpose();
  }
  return out;
}

// One space's side of the robust passes over a stretch: the measurements, their weights and
// the covariance scale read off the residuals.
template <typename S>
struct RobustState {
  std::vector<typename S::X> z;        // per frame of the stretch (gaps: a neighbour's)
  std::vector<double> weight, d2;      // per frame
  double scale = 1;
  Smoothed<S> fit;
};

template <typename S>
void InitRobust(const Stretch& s, const std::vector<typename S::X>& z_all, RobustState<S>* r) {
  const size_t n = s.frames.size();
  r->z.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const int m = s.measured[k];
    r->z[k] = m >= 0 ? z_all[m] : r->z[k - 1];  // a stretch starts at a measured frame
  }
  r->weight.assign(n, 1.0);
  r->d2.assign(n, 0.0);
}

// One pass: fits with the current weights and covariances, then re-weights (Cauchy before the
// last pass, the χ² gate for it). `cov_all` holds the measurements' covariances, unscaled.
template <typename S>
void RobustPass(const Stretch& s, const std::vector<Eigen::Matrix3d>& cov_all, const Model& model,
                const TrackSmootherOptions& options, int pass, RobustState<S>* r) {
  const size_t n = s.frames.size();
  std::vector<bool> use(n);
  std::vector<Eigen::Matrix3d> cov(n, Eigen::Matrix3d::Identity());
  for (size_t k = 0; k < n; ++k) {
    const int m = s.measured[k];
    use[k] = m >= 0 && r->weight[k] > 0;
    if (use[k]) cov[k] = cov_all[m] * (r->scale / r->weight[k]);
  }
  r->fit = FilterAndSmooth<S>(s, r->z, cov, use, model);
  if (pass == options.passes + 1) {  // the gated fit is the result
    for (size_t k = 0; k < n; ++k) r->weight[k] = use[k] ? 1.0 : 0.0;
    return;
  }
  std::vector<double> measured_d2;
  for (size_t k = 0; k < n; ++k) {
    const int m = s.measured[k];
    if (m < 0) continue;
    const Eigen::Vector3d e = S::Minus(r->z[k], r->fit.x[k]);
    r->d2[k] = e.dot(cov_all[m].ldlt().solve(e));
    measured_d2.push_back(r->d2[k]);
  }
  // The scale is read off a fit the kernel has already made robust (pass ≥ 1): the first,
  // unweighted fit is pulled towards every outlier, and its residuals would inflate it.
  constexpr double kChi2Median3 = 2.366;  // median of χ² with 3 degrees of freedom
  if (pass >= 1 && pass < options.passes) {
    std::nth_element(measured_d2.begin(), measured_d2.begin() + measured_d2.size() / 2,
                     measured_d2.end());
    r->scale = std::max(1.0, measured_d2[measured_d2.size() / 2] / kChi2Median3);
  }
  const double c2 = options.gate_chi2 / 2;
  for (size_t k = 0; k < n; ++k) {
    if (s.measured[k] < 0) continue;
    const double d2s = r->d2[k] / r->scale;
    r->weight[k] = pass < options.passes ? 1.0 / (1.0 + d2s / c2) : (d2s <= options.gate_chi2 ? 1.0 : 0.0);
  }
}

// The medoid of the positions, and of the rotations, of the measurements within `half` frames
// of each: a start for the covariances that one flipped measurement does not move.
std::vector<Pose> LocalMedoids(const std::vector<TrackMeasurement>& m, int half) {
  std::vector<Pose> out(m.size(), Pose::Identity());
  for (size_t i = 0; i < m.size(); ++i) {
    size_t best_t = i, best_r = i;
    double min_t = INFINITY, min_r = INFINITY;
    for (size_t a = 0; a < m.size(); ++a) {
      if (std::abs(m[a].frame - m[i].frame) > half) continue;
      double sum_t = 0, sum_r = 0;
      for (size_t b = 0; b < m.size(); ++b) {
        if (std::abs(m[b].frame - m[i].frame) > half) continue;
        sum_t += (m[a].world_from_body.translation() - m[b].world_from_body.translation()).norm();
        sum_r += RotationAngle(m[a].world_from_body.linear().transpose() * m[b].world_from_body.linear());
      }
      if (sum_t < min_t) min_t = sum_t, best_t = a;
      if (sum_r < min_r) min_r = sum_r, best_r = a;
    }
    out[i].linear() = m[best_r].world_from_body.linear();
    out[i].translation() = m[best_t].world_from_body.translation();
  }
  return out;
}

std::vector<Stretch> Stretches(const std::vector<TrackMeasurement>& m, double frame_period_s,
                               double max_gap_s) {
  std::vector<Stretch> out;
  for (size_t i = 0; i < m.size(); ++i) {
    const bool new_stretch = i == 0 || m[i].time_s - m[i - 1].time_s > max_gap_s + 1e-9;
    if (new_stretch) out.emplace_back();
    Stretch& s = out.back();
    if (!new_stretch) {
      // The frames between two measured ones, their times spread evenly between them.
      const int f0 = m[i - 1].frame, f1 = m[i].frame;
      const double t0 = m[i - 1].time_s, t1 = m[i].time_s;
      for (int f = f0 + 1; f < f1; ++f) {
        s.frames.push_back(f);
        s.times.push_back(f1 > f0 ? t0 + (t1 - t0) * (f - f0) / (f1 - f0) : t0 + frame_period_s);
        s.measured.push_back(-1);
      }
    }
    s.frames.push_back(m[i].frame);
    s.times.push_back(m[i].time_s);
    s.measured.push_back(static_cast<int>(i));
  }
  return out;
}

}  // namespace

SmoothedTrack SmoothTrack(const std::vector<TrackMeasurement>& measurements, double frame_period_s,
                          const TrackSmootherOptions& options, const MeasurementCovariance& covariance) {
  SmoothedTrack track;
  const size_t n = measurements.size();
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Matrix3d> rotations;
  for (const TrackMeasurement& m : measurements) {
    positions.push_back(m.world_from_body.translation());
    rotations.push_back(m.world_from_body.linear());
  }
  // A floor keeps every covariance invertible (a measurement of three collinear points has
  // no information about the roll around their line).
  const Eigen::Matrix3d floor = 1e-10 * Eigen::Matrix3d::Identity();
  std::vector<Eigen::Matrix3d> position_covs(n), rotation_covs(n);
  std::vector<Pose> where = covariance ? LocalMedoids(measurements, 5) : std::vector<Pose>{};
  const auto update_covariances = [&] {
    for (size_t i = 0; i < n; ++i) {
      const TrackMeasurement& m = measurements[i];
      Eigen::Matrix3d r = m.rotation_cov, p = m.position_cov;
      if (covariance) covariance(m.frame, where[i], &r, &p);
      rotation_covs[i] = r + floor;
      position_covs[i] = p + floor;
    }
  };
  update_covariances();
  const Model position_model{std::pow(options.acceleration_mps2, 2), INFINITY};
  // An Ornstein–Uhlenbeck angular velocity: stationary σ² = q τ / 2.
  const Model rotation_model{
      2 * std::pow(options.angular_rate_sigma_radps, 2) / options.angular_rate_time_s,
      options.angular_rate_time_s};
  std::vector<bool> position_ok(n), rotation_ok(n);
  for (const Stretch& s : Stretches(measurements, frame_period_s, options.max_gap_s)) {
    RobustState<PositionSpace> p;
    RobustState<RotationSpace> r;
    InitRobust(s, positions, &p);
    InitRobust(s, rotations, &r);
    for (int pass = 0; pass <= options.passes + 1; ++pass) {
      RobustPass(s, position_covs, position_model, options, pass, &p);
      RobustPass(s, rotation_covs, rotation_model, options, pass, &r);
      if (!covariance || pass == options.passes + 1) continue;
      // A measurement's covariance follows from where the body is, not from where that
      // measurement says it is: a pose flipped towards the camera would claim the precision of
      // a near object.
      for (size_t k = 0; k < s.frames.size(); ++k) {
        const int m = s.measured[k];
        if (m < 0) continue;
        where[m].linear() = r.fit.x[k];
        where[m].translation() = p.fit.x[k];
      }
      update_covariances();
    }
    for (size_t k = 0; k < s.frames.size(); ++k) {
      TrackState state;
      state.frame = s.frames[k];
      state.time_s = s.times[k];
      state.world_from_body.linear() = r.fit.x[k];
      state.world_from_body.translation() = p.fit.x[k];
      state.velocity = p.fit.v[k];
      state.angular_velocity = r.fit.v[k];
      state.position_cov = p.fit.P[k].topLeftCorner<3, 3>();
      state.rotation_cov = r.fit.P[k].topLeftCorner<3, 3>();
      const int m = s.measured[k];
      if (m >= 0) {
        position_ok[m] = p.weight[k] > 0;
        rotation_ok[m] = r.weight[k] > 0;
      }
      state.measured = m >= 0 && position_ok[m] && rotation_ok[m];
      track.states.push_back(state);
    }
    track.position_scale = std::max(track.position_scale, p.scale);
    track.rotation_scale = std::max(track.rotation_scale, r.scale);
  }
  for (size_t i = 0; i < n; ++i) {
    track.rejected_positions += !position_ok[i];
    track.rejected_rotations += !rotation_ok[i];
  }
  return track;
}

}  // namespace cslam
