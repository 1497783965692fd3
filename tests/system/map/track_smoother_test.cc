#include "system/map/track_smoother.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/rigid.h"

namespace cslam {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kPeriod = 0.1;  // 10 Hz

// A car (y down, z forward) at `speed` m/s turning at `yaw_rate` rad/s about the vertical
// axis, starting 40 m ahead of the world origin.
Pose TrueCar(int frame, double speed, double yaw_rate) {
  const double t = frame * kPeriod;
  const double yaw = yaw_rate * t;
  Pose p = Pose::Identity();
  p.linear() = ExpSO3(Eigen::Vector3d(0, yaw, 0));
  if (std::abs(yaw_rate) < 1e-12) {
    p.translation() = Eigen::Vector3d(0, 1, 40 + speed * t);
  } else {
    const double r = speed / yaw_rate;
    p.translation() = Eigen::Vector3d(r * (1 - std::cos(yaw)), 1, 40 + r * std::sin(yaw));
  }
  return p;
}

// Measurements with noise drawn from their own covariance (position σ_p, rotation σ_r).
std::vector<TrackMeasurement> Measure(const std::vector<int>& frames, double speed, double yaw_rate,
                                      double sigma_p, double sigma_r, std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  std::vector<TrackMeasurement> out;
  for (int f : frames) {
    TrackMeasurement m;
    m.frame = f;
    m.time_s = f * kPeriod;
    const Pose truth = TrueCar(f, speed, yaw_rate);
    m.world_from_body.linear() =
        ExpSO3(sigma_r * Eigen::Vector3d(n(rng), n(rng), n(rng))) * truth.linear();
    m.world_from_body.translation() =
        truth.translation() + sigma_p * Eigen::Vector3d(n(rng), n(rng), n(rng));
    m.position_cov = sigma_p * sigma_p * Eigen::Matrix3d::Identity();
    m.rotation_cov = sigma_r * sigma_r * Eigen::Matrix3d::Identity();
    out.push_back(m);
  }
  return out;
}

std::vector<int> Range(int first, int last) {
  std::vector<int> v;
  for (int f = first; f <= last; ++f) v.push_back(f);
  return v;
}

double LargestTurnDeg(const SmoothedTrack& t) {
  double largest = 0;
  for (size_t k = 1; k < t.states.size(); ++k)
    largest = std::max(largest, RotationAngle(t.states[k - 1].world_from_body.linear().transpose() *
                                              t.states[k].world_from_body.linear()) / kDeg);
  return largest;
}

TEST(TrackSmoother, AFarCarsFlippedHeadingsAreRefusedAndItsTrackStaysOneACarCouldDrive) {
  std::mt19937 rng(7);
  std::vector<TrackMeasurement> m = Measure(Range(0, 59), 10, 0, 0.3, 2 * kDeg, rng);
  // A quarter of the frames come from a window that flipped the body by 170° about a point
  // 20 m away (the cluster frame's origin at the camera): heading and place both wrong.
  int flipped = 0;
  for (size_t i = 3; i < m.size(); i += 4, ++flipped) {
    const Pose flip = Pose(Eigen::Translation3d(0, 1, 20)) *
                      Pose(Eigen::AngleAxisd(170 * kDeg, Eigen::Vector3d::UnitY())) *
                      Pose(Eigen::Translation3d(0, -1, -20));
    m[i].world_from_body = flip * m[i].world_from_body;
  }
  const SmoothedTrack t = SmoothTrack(m, kPeriod);
  ASSERT_EQ(t.states.size(), 60u);
  EXPECT_GE(t.rejected_rotations, flipped);
  EXPECT_GE(t.rejected_positions, flipped);
  EXPECT_LE(t.rejected_rotations, flipped + 3);
  // Smoothed, the track is closer to the truth than the good measurements themselves are
  // (their RMS errors: 0.3·√3 = 0.52 m, 2°·√3 = 3.5°).
  double se_p = 0, se_r = 0;
  for (const TrackState& s : t.states) {
    const Pose truth = TrueCar(s.frame, 10, 0);
    se_p += (s.world_from_body.translation() - truth.translation()).squaredNorm();
    se_r += std::pow(RotationAngle(truth.linear().transpose() * s.world_from_body.linear()), 2);
  }
  EXPECT_LT(std::sqrt(se_p / 60), 0.5 * 0.3 * std::sqrt(3.0));
  EXPECT_LT(std::sqrt(se_r / 60) / kDeg, 0.5 * 2 * std::sqrt(3.0));
  EXPECT_LT(LargestTurnDeg(t), 1.0);
  // Its speed, read off 0.3 m position noise at 10 Hz, is 10 m/s on the average and within
  // 1.5 m/s at any frame (the track's two ends are seen from one side only).
  double speed_sum = 0;
  for (const TrackState& s : t.states) {
    EXPECT_NEAR(s.velocity.norm(), 10, 1.5) << s.frame;
    speed_sum += s.velocity.norm();
  }
  EXPECT_NEAR(speed_sum / t.states.size(), 10, 0.2);
}

TEST(TrackSmoother, ATurningCarIsFollowedNotStraightened) {
  std::mt19937 rng(11);
  const double yaw_rate = 0.4;  // rad/s: a right-angle turn in 4 s
  const std::vector<TrackMeasurement> m = Measure(Range(0, 79), 8, yaw_rate, 0.2, 1 * kDeg, rng);
  const SmoothedTrack t = SmoothTrack(m, kPeriod);
  EXPECT_LE(t.rejected_rotations, 2);
  EXPECT_LE(t.rejected_positions, 2);
  // The turn is followed: the smoothed heading is nearer the truth than the measurements
  // (RMS 1°·√3 = 1.7°), and never lags by a measurement's worst error.
  double se_r = 0, worst_heading = 0, worst_position = 0;
  for (const TrackState& s : t.states) {
    const Pose truth = TrueCar(s.frame, 8, yaw_rate);
    const double r = RotationAngle(truth.linear().transpose() * s.world_from_body.linear()) / kDeg;
    se_r += r * r;
    worst_heading = std::max(worst_heading, r);
    worst_position = std::max(worst_position, (s.world_from_body.translation() - truth.translation()).norm());
  }
  EXPECT_LT(std::sqrt(se_r / t.states.size()), 0.6 * std::sqrt(3.0));
  EXPECT_LT(worst_heading, 3.0);
  EXPECT_LT(worst_position, 0.4);
  EXPECT_NEAR(t.states[40].angular_velocity.y(), yaw_rate, 0.1);
}

TEST(TrackSmoother, AGapUpToMaxGapIsPredictedAndALongerOneStartsANewStretch) {
  std::mt19937 rng(3);
  std::vector<int> frames = Range(0, 19);
  for (int f : Range(30, 49)) frames.push_back(f);  // 1 s gap: bridged
  for (int f : Range(80, 99)) frames.push_back(f);  // 3 s gap: split
  const SmoothedTrack t = SmoothTrack(Measure(frames, 10, 0, 0.3, 2 * kDeg, rng), kPeriod);
  ASSERT_EQ(t.states.size(), 50u + 20u);
  EXPECT_EQ(t.states[49].frame, 49);
  EXPECT_EQ(t.states[50].frame, 80);
  const TrackState& hidden = t.states[25];
  EXPECT_EQ(hidden.frame, 25);
  EXPECT_FALSE(hidden.measured);
  EXPECT_TRUE(t.states[15].measured);
  EXPECT_LT((hidden.world_from_body.translation() - TrueCar(25, 10, 0).translation()).norm(), 0.5);
  // Less sure in the middle of the gap than where it is seen.
  EXPECT_GT(hidden.position_cov.trace(), 2 * t.states[15].position_cov.trace());
}

TEST(TrackSmoother, ItsPositionUncertaintyIsHonest) {
  // Over many tracks with noise drawn from the stated covariances, the squared error weighted
  // by the smoothed covariance averages 3 (three degrees of freedom) when that covariance is
  // right; an over- or under-confident smoother is far from it.
  std::mt19937 rng(5);
  double nees = 0;
  int n = 0;
  for (int run = 0; run < 20; ++run) {
    const SmoothedTrack t = SmoothTrack(Measure(Range(0, 49), 10, 0.1, 0.5, 3 * kDeg, rng), kPeriod);
    for (const TrackState& s : t.states) {
      const Eigen::Vector3d e = s.world_from_body.translation() - TrueCar(s.frame, 10, 0.1).translation();
      nees += e.dot(s.position_cov.ldlt().solve(e));
      ++n;
    }
  }
  EXPECT_GT(nees / n, 1.5);
  EXPECT_LT(nees / n, 6.0);
}

TEST(TrackSmoother, OptionsExplainABadValue) {
  TrackSmootherOptions o;
  o.acceleration_mps2 = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.max_gap_s = -1;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.angular_rate_time_s = NAN;
  EXPECT_THROW(o.Check(), ConfigError);
  EXPECT_NO_THROW(TrackSmootherOptions{}.Check());
}

}  // namespace
}  // namespace cslam
