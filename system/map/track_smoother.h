#pragma once
// A robust constant-velocity smoother for one object's track: what the windows cannot
// determine about a body (a far car's heading) comes from what the body can physically do.
// Position and rotation are smoothed each on its own (R³, and SO(3) perturbed on the left in
// the world frame) by a Kalman filter and a Rauch–Tung–Striebel smoother whose process noise
// is a white acceleration bounded by the body's physics. Each frame's measurement carries the
// covariance its landmarks give it; a measurement the model cannot explain (a heading flipped
// by 170° between frames, a position 30 m off) is down-weighted by a Cauchy kernel over a few
// passes and finally rejected by a χ² gate, so noise does not make the track.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"

namespace cslam {

/// What a tracked body can physically do, and how the measurements are judged.
struct TrackSmootherOptions {
  /// Spectral density of the position's white acceleration, as the velocity change it allows
  /// in one second (1 σ, m/s²; 3: a road vehicle braking or speeding up hard in town).
  double acceleration_mps2 = 3.0;
  /// Bodies turn, but do not spin: the angular velocity is a mean-reverting process with this
  /// standard deviation (rad/s; 0.5: a car at 5 m/s on a 10 m radius) ...
  double angular_rate_sigma_radps = 0.5;
  /// ... and this correlation time (s; how long a body keeps turning: a turn at a junction
  /// lasts a few seconds). Its yaw acceleration is then about σ·√(2/τ) = 0.5 rad/s² (1 σ).
  /// Without measurements that say otherwise, a body's heading stays.
  double angular_rate_time_s = 2.0;
  /// Vehicles move where they point: the object adjustment holds each frame's velocity, seen
  /// in the body frame, to one direction of travel (either sign: a car may reverse), up to
  /// this lateral velocity (1 σ, m/s; 0: off). 2: a road vehicle's body-frame origin (its
  /// points' centroid, metres ahead of the rear axle) slides sideways at ω × that lever in a
  /// turn, 1 m/s at 0.5 rad/s and 2 m, plus the tyres' slip. A pedestrian's or a pushed box's
  /// sidestep at walking pace stays within it. A far car's keypoints hardly fix its heading;
  /// its path fixes its direction of travel.
  double lateral_velocity_mps = 2.0;
  /// Vehicles turn about the vertical; they hardly pitch or roll. In the object adjustment the
  /// angular velocity about the body's two horizontal axes has this standard deviation (rad/s;
  /// 0: the same as about the vertical, angular_rate_sigma_radps). 0.1: a car's pitch in hard
  /// braking or its roll in a quick lane change, 2–3° in about half a second. The vertical is
  /// the world's y axis, the first camera frame's: a vehicle's camera is mounted level. A far
  /// car's keypoints tip it by fractions of a degree each frame; its suspension does not.
  double tilt_rate_sigma_radps = 0.1;
  /// A measurement whose squared Mahalanobis distance from the smoothed track exceeds this
  /// (3 dof: 16.27 is the 99.9 % quantile) is rejected in the final pass.
  double gate_chi2 = 16.27;
  /// Re-weighting passes before the gated one (Cauchy kernel of scale gate_chi2 / 2). From the
  /// second on, the measurements' covariances are scaled up by the median squared Mahalanobis
  /// residual over its 3-dof median (2.37) when that exceeds 1: the landmarks give a covariance's shape, and a
  /// window's pose errs by more than its keypoints' noise (drift, a wrong shape at range).
  int passes = 4;
  /// Frames without a measurement are predicted from the model across gaps up to this long;
  /// a longer gap starts a new, independent stretch and leaves the frames between without a pose.
  double max_gap_s = 2.0;
  void Check() const;
  void Load(OptionsReader& r);
};

/// One measured frame of a body: its pose and the 3×3 covariances of its rotation (left
/// perturbation, world frame, rad²) and of its position (m²).
struct TrackMeasurement {
  int frame = 0;
  double time_s = 0;
  Pose world_from_body = Pose::Identity();
  Eigen::Matrix3d rotation_cov = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d position_cov = Eigen::Matrix3d::Identity();
  /// The body's turn since the previous measurement (world, left), where it was measured
  /// apart from the orientation: a far body's windows agree on how it turns long before they
  /// agree on where it points. When any measurement has one, the rotation is smoothed from
  /// these turn rates, starting at each stretch's first orientation; the orientations are not
  /// used after it.
  std::optional<Eigen::Matrix3d> turn;
};

/// The smoothed body at one frame.
struct TrackState {
  int frame = 0;
  double time_s = 0;
  Pose world_from_body = Pose::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< m/s, world
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, world
  Eigen::Matrix3d position_cov = Eigen::Matrix3d::Zero();      ///< m²
  Eigen::Matrix3d rotation_cov = Eigen::Matrix3d::Zero();      ///< rad²
  bool measured = false;  ///< a measurement at this frame was used (not rejected, not a gap)
};

/// The smoothed track and what was made of the measurements.
struct SmoothedTrack {
  std::vector<TrackState> states;  ///< ascending frames, every frame of each stretch
  int rejected_positions = 0;      ///< measurements whose position the final gate refused
  int rejected_rotations = 0;      ///< ... whose rotation it refused
  /// The factor the measurements' covariances were scaled by (≥ 1), position and rotation.
  double position_scale = 1, rotation_scale = 1;
};

/// A measurement's covariances (rotation, position) when the body is at `world_from_body` at
/// `frame`; false leaves the measurement's own.
using MeasurementCovariance = std::function<bool(int frame, const Pose& world_from_body,
                                                 Eigen::Matrix3d* rotation_cov,
                                                 Eigen::Matrix3d* position_cov)>;

/// Smooths `measurements` (ascending, distinct frames). `frame_period_s` is the time between
/// frames, for the frames without a measurement inside a stretch. With `covariance`, each
/// measurement's covariances are evaluated where the body is: first at the medoid of the
/// measurements within 5 frames, then after each pass at the smoothed pose, so a measurement
/// that misplaces the body does not choose its own precision.
SmoothedTrack SmoothTrack(const std::vector<TrackMeasurement>& measurements,
                          double frame_period_s, const TrackSmootherOptions& options = {},
                          const MeasurementCovariance& covariance = {});

}  // namespace cslam
