#include "system/map/track_smoother.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "system/map/medoid.h"

namespace cslam {

void TrackSmootherOptions::Check() const {
  CheckOption(std::isfinite(acceleration_mps2) && acceleration_mps2 > 0, "acceleration_mps2",
              "must be positive (m/s² of white acceleration a body can take)", acceleration_mps2);
  CheckOption(std::isfinite(angular_rate_sigma_radps) && angular_rate_sigma_radps > 0,
              "angular_rate_sigma_radps", "must be positive (rad/s)", angular_rate_sigma_radps);
  CheckOption(std::isfinite(angular_rate_time_s) && angular_rate_time_s > 0,
              "angular_rate_time_s", "must be positive (s)", angular_rate_time_s);
  CheckOption(std::isfinite(lateral_velocity_mps) && lateral_velocity_mps >= 0,
              "lateral_velocity_mps", "must be >= 0 (m/s; 0: off)", lateral_velocity_mps);
  CheckOption(std::isfinite(tilt_rate_sigma_radps) && tilt_rate_sigma_radps >= 0,
              "tilt_rate_sigma_radps", "must be >= 0 (rad/s; 0: as about the vertical)",
              tilt_rate_sigma_radps);
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
  r.Read("lateral_velocity_mps", &lateral_velocity_mps);
  r.Read("tilt_rate_sigma_radps", &tilt_rate_sigma_radps);
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
  using Z = X;  // what is measured: the position
  static constexpr bool kOnVelocity = false;
  static X Plus(const X& x, const Eigen::Vector3d& d) { return x + d; }
  static Eigen::Vector3d Minus(const X& a, const X& b) { return a - b; }
  static constexpr double kInitialSigma = 1e3;          // m: the first measurement decides
  static constexpr double kInitialVelocitySigma = 30;  // m/s: any road speed
};
struct RotationSpace {
  using X = Eigen::Matrix3d;
  using Z = X;  // what is measured: the rotation
  static constexpr bool kOnVelocity = false;
  static X Plus(const X& x, const Eigen::Vector3d& d) { return ExpSO3(d) * x; }
  static Eigen::Vector3d Minus(const X& a, const X& b) { return LogSO3(a * b.transpose()); }
  static constexpr double kInitialSigma = M_PI;
  // rad/s; only for a model without mean reversion (the angular model has one).
  static constexpr double kInitialVelocitySigma = 1.0;
};
// Rotations whose measurements are turn rates: the orientation starts at the first
// measurement's (the body frame's axes, exactly) and follows the integrated angular velocity.
struct TurnRateSpace : RotationSpace {
  using Z = Eigen::Vector3d;  // rad/s, world
  static constexpr bool kOnVelocity = true;
  static constexpr double kInitialSigma = 0;
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
Smoothed<S> FilterAndSmooth(const Stretch& s, const typename S::X& x0,
                            const std::vector<typename S::Z>& z,
                            const std::vector<Eigen::Matrix3d>& cov, const std::vector<bool>& use,
                            const Model& model) {
  const size_t n = s.frames.size();
  std::vector<typename S::X> x_pred(n), x_filt(n);
  std::vector<Eigen::Vector3d> v_pred(n), v_filt(n);
  std::vector<Matrix6d> P_pred(n), P_filt(n);
  for (size_t k = 0; k < n; ++k) {
    if (k == 0) {
      x_pred[0] = x0;
      v_pred[0].setZero();
      P_pred[0].setZero();
      P_pred[0].topLeftCorner<3, 3>() = std::pow(S::kInitialSigma, 2) * Eigen::Matrix3d::Identity();
      // A mean-reverting velocity is, before any measurement, in its stationary spread
      // (q τ / 2): a body first seen is no likelier to spin than one seen for a while.
      const double v0 = std::isfinite(model.tau) ? model.q * model.tau / 2
                                                 : std::pow(S::kInitialVelocitySigma, 2);
      P_pred[0].bottomRightCorner<3, 3>() = v0 * Eigen::Matrix3d::Identity();
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
    // H selects the measured half of the state: the position/rotation or the velocity.
    constexpr int h = S::kOnVelocity ? 3 : 0;
    Eigen::Vector3d y;
    if constexpr (S::kOnVelocity)
      y = z[k] - v_pred[k];
    else
      y = S::Minus(z[k], x_pred[k]);
    const Eigen::Matrix3d innovation = P_pred[k].template block<3, 3>(h, h) + cov[k];
    const Eigen::Matrix<double, 6, 3> K =
        P_pred[k].template middleCols<3>(h) * innovation.ldlt().solve(Eigen::Matrix3d::Identity());
    const Vector6d d = K * y;
    x_filt[k] = S::Plus(x_pred[k], d.head<3>());
    v_filt[k] = v_pred[k] + d.tail<3>();
    Matrix6d IKH = Matrix6d::Identity();
    IKH.template middleCols<3>(h) -= K;
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
  typename S::X x0;                    // the state at the stretch's first frame, to start from
  std::vector<typename S::Z> z;        // per frame of the stretch (gaps: a neighbour's)
  std::vector<double> weight, d2;      // per frame
  double scale = 1;
  Smoothed<S> fit;
};

template <typename S>
void InitRobust(const Stretch& s, const typename S::X& x0, const std::vector<typename S::Z>& z_all,
                RobustState<S>* r) {
  const size_t n = s.frames.size();
  r->x0 = x0;
  r->z.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const int m = s.measured[k];
    r->z[k] = m >= 0 ? z_all[m] : r->z[k - 1];  // a stretch starts at a measured frame
  }
  r->weight.assign(n, 1.0);
  // A turn rate is measured between two frames: the stretch's first has none.
  if constexpr (S::kOnVelocity) r->weight[0] = 0;
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
  r->fit = FilterAndSmooth<S>(s, r->x0, r->z, cov, use, model);
  if (pass == options.passes + 1) {  // the gated fit is the result
    for (size_t k = 0; k < n; ++k) r->weight[k] = use[k] ? 1.0 : 0.0;
    return;
  }
  std::vector<double> measured_d2;
  for (size_t k = 0; k < n; ++k) {
    const int m = s.measured[k];
    if (m < 0 || (S::kOnVelocity && k == 0)) continue;
    Eigen::Vector3d e;
    if constexpr (S::kOnVelocity)
      e = r->z[k] - r->fit.v[k];
    else
      e = S::Minus(r->z[k], r->fit.x[k]);
    r->d2[k] = e.dot(cov_all[m].ldlt().solve(e));
    measured_d2.push_back(r->d2[k]);
  }
  // The scale is read off a fit the kernel has already made robust (pass ≥ 1): the first,
  // unweighted fit is pulled towards every outlier, and its residuals would inflate it.
  constexpr double kChi2Median3 = 2.366;  // median of χ² with 3 degrees of freedom
  if (pass >= 1 && pass < options.passes && !measured_d2.empty()) {
    std::nth_element(measured_d2.begin(), measured_d2.begin() + measured_d2.size() / 2,
                     measured_d2.end());
    r->scale = std::max(1.0, measured_d2[measured_d2.size() / 2] / kChi2Median3);
  }
  const double c2 = options.gate_chi2 / 2;
  for (size_t k = 0; k < n; ++k) {
    if (s.measured[k] < 0 || (S::kOnVelocity && k == 0)) continue;
    const double d2s = r->d2[k] / r->scale;
    r->weight[k] = pass < options.passes ? 1.0 / (1.0 + d2s / c2) : (d2s <= options.gate_chi2 ? 1.0 : 0.0);
  }
}

// The medoid of the positions, and of the rotations, of the measurements within `half` frames
// of each: a start for the covariances that one flipped measurement does not move.
std::vector<Pose> LocalMedoids(const std::vector<TrackMeasurement>& m, int half) {
  std::vector<Pose> out(m.size(), Pose::Identity());
  size_t first = 0, last = 0;  // the measurements within `half` frames of i (m is ascending)
  for (size_t i = 0; i < m.size(); ++i) {
    while (m[i].frame - m[first].frame > half) ++first;
    while (last < m.size() && m[last].frame - m[i].frame <= half) ++last;
    const size_t t = MedoidIndex(first, last, [&](size_t a, size_t b) {
      return (m[a].world_from_body.translation() - m[b].world_from_body.translation()).norm();
    });
    const size_t r = MedoidIndex(first, last, [&](size_t a, size_t b) {
      return RotationAngle(m[a].world_from_body.linear().transpose() * m[b].world_from_body.linear());
    });
    out[i].linear() = m[r].world_from_body.linear();
    out[i].translation() = m[t].world_from_body.translation();
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

// What SmoothTrack shares with one stretch's passes.
struct TrackInputs {
  const std::vector<TrackMeasurement>& measurements;
  const TrackSmootherOptions& options;
  const MeasurementCovariance& covariance;
  Model position_model, rotation_model;
  std::vector<Eigen::Vector3d> positions, turn_rates;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Matrix3d> position_covs, rotation_covs, turn_rate_covs;
  std::vector<Pose> where;  // where each measurement's covariance is evaluated
  std::vector<bool> position_ok, rotation_ok;
};

// The measurements' covariances at `in->where`; a turn rate's from its two ends' rotations.
void UpdateCovariances(TrackInputs* in) {
  // A floor keeps every covariance invertible (a measurement of three collinear points has
  // no information about the roll around their line).
  const Eigen::Matrix3d floor = 1e-10 * Eigen::Matrix3d::Identity();
  const auto& m = in->measurements;
  for (size_t i = 0; i < m.size(); ++i) {
    Eigen::Matrix3d r = m[i].rotation_cov, p = m[i].position_cov;
    if (in->covariance) in->covariance(m[i].frame, in->where[i], &r, &p);
    in->rotation_covs[i] = r + floor;
    in->position_covs[i] = p + floor;
  }
  for (size_t i = 1; i < m.size(); ++i) {
    const double dt = std::max(m[i].time_s - m[i - 1].time_s, 1e-6);
    in->turn_rate_covs[i] = (in->rotation_covs[i] + in->rotation_covs[i - 1]) / (dt * dt);
  }
}

template <typename R>
void SmoothStretch(const Stretch& s, TrackInputs* in, SmoothedTrack* track) {
  const TrackSmootherOptions& options = in->options;
  RobustState<PositionSpace> p;
  RobustState<R> r;
  InitRobust(s, in->positions[s.measured[0]], in->positions, &p);
  const std::vector<Eigen::Matrix3d>* rotation_covs = &in->rotation_covs;
  if constexpr (R::kOnVelocity) {
    InitRobust(s, in->rotations[s.measured[0]], in->turn_rates, &r);
    rotation_covs = &in->turn_rate_covs;
    for (size_t k = 1; k < s.frames.size(); ++k)  // frames whose turn no window measured
      if (s.measured[k] >= 0 && !in->measurements[s.measured[k]].turn) r.weight[k] = 0;
  } else {
    InitRobust(s, in->rotations[s.measured[0]], in->rotations, &r);
  }
  for (int pass = 0; pass <= options.passes + 1; ++pass) {
    RobustPass(s, in->position_covs, in->position_model, options, pass, &p);
    RobustPass(s, *rotation_covs, in->rotation_model, options, pass, &r);
    if (!in->covariance || pass == options.passes + 1) continue;
    // A measurement's covariance follows from where the body is, not from where that
    // measurement says it is: a pose flipped towards the camera would claim the precision of
    // a near object.
    for (size_t k = 0; k < s.frames.size(); ++k) {
      const int m = s.measured[k];
      if (m < 0) continue;
      in->where[m].linear() = r.fit.x[k];
      in->where[m].translation() = p.fit.x[k];
    }
    UpdateCovariances(in);
  }
  for (size_t k = 0; k < s.frames.size(); ++k) {
    TrackState state;
    state.frame = s.frames[k];
    state.time_s = s.times[k];
    state.world_from_body.linear() = r.fit.x[k];
    state.world_from_body.translation() = p.fit.x[k];
    state.velocity = p.fit.v[k];
    state.angular_velocity = r.fit.v[k];
    state.position_cov = p.fit.P[k].template topLeftCorner<3, 3>();
    state.rotation_cov = r.fit.P[k].template topLeftCorner<3, 3>();
    const int m = s.measured[k];
    if (m >= 0) {
      in->position_ok[m] = p.weight[k] > 0;
      // A turn rate left unused for want of a measurement is no refusal.
      in->rotation_ok[m] = r.weight[k] > 0 || (R::kOnVelocity && (k == 0 || !in->measurements[m].turn));
    }
    state.measured = m >= 0 && in->position_ok[m] && in->rotation_ok[m];
    track->states.push_back(state);
  }
  track->position_scale = std::max(track->position_scale, p.scale);
  track->rotation_scale = std::max(track->rotation_scale, r.scale);
}

}  // namespace

SmoothedTrack SmoothTrack(const std::vector<TrackMeasurement>& measurements, double frame_period_s,
                          const TrackSmootherOptions& options, const MeasurementCovariance& covariance) {
  SmoothedTrack track;
  const size_t n = measurements.size();
  TrackInputs in{measurements, options, covariance, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}};
  in.position_model = {std::pow(options.acceleration_mps2, 2), INFINITY};
  // An Ornstein–Uhlenbeck angular velocity: stationary σ² = q τ / 2.
  in.rotation_model = {2 * std::pow(options.angular_rate_sigma_radps, 2) / options.angular_rate_time_s,
                       options.angular_rate_time_s};
  bool turns = false;
  for (size_t i = 0; i < n; ++i) {
    const TrackMeasurement& m = measurements[i];
    in.positions.push_back(m.world_from_body.translation());
    in.rotations.push_back(m.world_from_body.linear());
    Eigen::Vector3d rate = Eigen::Vector3d::Zero();
    if (i > 0 && m.turn) {
      rate = LogSO3(*m.turn) / std::max(m.time_s - measurements[i - 1].time_s, 1e-6);
      turns = true;
    }
    in.turn_rates.push_back(rate);
  }
  in.position_covs.resize(n);
  in.rotation_covs.resize(n);
  in.turn_rate_covs.assign(n, Eigen::Matrix3d::Identity());
  in.where = covariance ? LocalMedoids(measurements, 5) : std::vector<Pose>{};
  in.position_ok.assign(n, false);
  in.rotation_ok.assign(n, false);
  UpdateCovariances(&in);
  for (const Stretch& s : Stretches(measurements, frame_period_s, options.max_gap_s)) {
    if (turns)
      SmoothStretch<TurnRateSpace>(s, &in, &track);
    else
      SmoothStretch<RotationSpace>(s, &in, &track);
  }
  for (size_t i = 0; i < n; ++i) {
    track.rejected_positions += !in.position_ok[i];
    track.rejected_rotations += !in.rotation_ok[i];
  }
  return track;
}

}  // namespace cslam
