#include "system/map/reappearance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/system/map/car_points.h"

namespace cslam {
namespace {

constexpr double kPeriod = 0.1;  // 10 Hz, as KITTI

using testing::CarPoints;

// A car's motion from `start`: heading `yaw` about the vertical (0: along z), speeding up.
struct Drive {
  int start = 0;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  double yaw = 0, speed = 8, accel = 1.0, yaw_rate = 0.1;  // rad, m/s, m/s², rad/s

  Pose WorldFromBody(int frame) const {
    // Integrated in small steps: speed and heading both change along the way.
    Eigen::Vector3d p = at;
    const int steps = 20 * (frame - start);
    const double dt = kPeriod / 20;
    for (int k = 0; k < steps; ++k) {
      const double t = (k + 0.5) * dt, h = yaw + yaw_rate * t;
      p += (speed + accel * t) * dt * Eigen::Vector3d(std::sin(h), 0, std::cos(h));
    }
    Pose pose = Pose::Identity();
    pose.linear() =
        Eigen::AngleAxisd(yaw + yaw_rate * (frame - start) * kPeriod, Eigen::Vector3d::UnitY())
            .toRotationMatrix();
    pose.translation() = p;
    return pose;
  }
};

// world_from_cluster over [begin, end): the body seen through an arbitrary cluster frame
// (`body_from_cluster`), each pose disturbed by `noise_m` (per axis) and a little rotation.
std::map<int, Pose> Track(const Drive& d, int begin, int end, const Pose& body_from_cluster,
                          double noise_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, 1);
  std::map<int, Pose> t;
  for (int f = begin; f < end; ++f) {
    Pose noise = Pose::Identity();
    noise.translation() = noise_m * Eigen::Vector3d(n(rng), n(rng), n(rng));
    noise.linear() = ExpSO3(0.005 * Eigen::Vector3d(n(rng), n(rng), n(rng)));
    t[f] = noise * d.WorldFromBody(f) * body_from_cluster;
  }
  return t;
}

std::vector<Eigen::Vector3d> InCluster(const std::vector<Eigen::Vector3d>& body_points,
                                       const Pose& body_from_cluster) {
  std::vector<Eigen::Vector3d> p;
  for (const auto& b : body_points) p.push_back(body_from_cluster.inverse() * b);
  return p;
}

ReappearanceGate Gate() {
  ReappearanceGate g;
  g.frame_period_s = kPeriod;
  return g;
}

Pose Offset(double yaw, double x, double y, double z) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

const Drive kCar{0, Eigen::Vector3d(5, 0, 20)};

TEST(Reappearance, ACarBackFromTwoSecondsBehindAnOccluderIsWhereItsMotionCarriesIt) {
  const std::vector<Eigen::Vector3d> body = CarPoints(1);
  const Pose a_frame = Offset(0.3, 1, -1, 0.5), b_frame = Offset(-0.7, -2, 0.5, 3);
  // Seen over frames 0..40, hidden for 2 s, back from frame 61 on new tracks.
  const auto a = Track(kCar, 0, 41, a_frame, 0.1, 2);
  const auto b = Track(kCar, 61, 90, b_frame, 0.1, 3);
  const Reappearance r =
      CompareAcrossGap(a, InCluster(body, a_frame), b, InCluster(body, b_frame), Gate());
  EXPECT_EQ(r.gap_frames, 21);
  EXPECT_EQ(r.compared, 10);
  EXPECT_TRUE(r.Reachable()) << r.distance_m << " m of " << r.allowed_m << ", speed change "
                             << r.speed_change_mps << " of " << r.allowed_speed_change_mps;
  // Its velocity changed as the drive says between the middles of a's fit and of b's first
  // frames (speeding up and turning: ~4 m/s).
  auto velocity = [](int from, int to) -> Eigen::Vector3d {
    return (kCar.WorldFromBody(to).translation() - kCar.WorldFromBody(from).translation()) /
           ((to - from) * kPeriod);
  };
  EXPECT_NEAR(r.speed_change_mps, (velocity(62, 64) - velocity(35, 36)).norm(), 0.7);
  // b's frame lands on a's: the body's points agree to the noise and the turn over the gap.
  const Pose truth = a_frame.inverse() * b_frame;
  EXPECT_LT((r.a_from_b.translation() - truth.translation()).norm(), 0.3);
  // Not carrying the turn on over the gap would miss by its 0.2 rad.
  EXPECT_LT(RotationAngle(r.a_from_b.linear() * truth.linear().transpose()), 0.1);
}

TEST(Reappearance, TheCarFollowingTwoSecondsBehindIsNotTheOneThatVanished) {
  // It reaches the place where the first car vanished about when that one is back in view.
  const std::vector<Eigen::Vector3d> body = CarPoints(1);
  Drive follower = kCar;
  follower.start = 20;
  const auto a = Track(kCar, 0, 41, Pose::Identity(), 0.1, 2);
  const auto b = Track(follower, 61, 90, Pose::Identity(), 0.1, 3);
  const Reappearance r = CompareAcrossGap(a, body, b, body, Gate());
  EXPECT_EQ(r.compared, 10);
  EXPECT_GT(r.distance_m, 10);
  EXPECT_FALSE(r.Reachable());
}

TEST(Reappearance, ACarCrossingWhereTheOldOneWouldBeDrivesTooDifferentlyToBeIt) {
  const std::vector<Eigen::Vector3d> body = CarPoints(1);
  const auto a = Track(kCar, 0, 41, Pose::Identity(), 0.1, 2);
  // From frame 61 on, a car drives across the old one's road at 12 m/s, at the place the old one
  // is then.
  Drive crossing{61, kCar.WorldFromBody(61).translation(), M_PI / 2, 12, 0, 0};
  const auto b = Track(crossing, 61, 90, Pose::Identity(), 0.1, 3);
  const Reappearance r = CompareAcrossGap(a, body, b, body, Gate());
  EXPECT_EQ(r.compared, 10);
  EXPECT_LE(r.distance_m, r.allowed_m);                       // the place would do...
  EXPECT_GT(r.speed_change_mps, r.allowed_speed_change_mps);  // ... the velocity does not
  EXPECT_FALSE(r.Reachable());
}

TEST(Reappearance, TracksThatOverlapOrLieTooFarApartInTimeAreNotCompared) {
  const std::vector<Eigen::Vector3d> body = CarPoints(1);
  const auto a = Track(kCar, 0, 41, Pose::Identity(), 0.0, 2);
  auto compared = [&](int begin, const ReappearanceGate& gate) {
    return CompareAcrossGap(a, body, Track(kCar, begin, 90, Pose::Identity(), 0.0, 3), body, gate)
        .compared;
  };
  EXPECT_EQ(compared(40, Gate()), 0);  // overlaps
  EXPECT_EQ(compared(71, Gate()), 0);  // 3.1 s after: longer than max_gap_s
  EXPECT_GT(compared(50, Gate()), 0);
  ReappearanceGate off = Gate();
  off.max_gap_s = 0;
  EXPECT_EQ(compared(50, off), 0);
}

}  // namespace
}  // namespace cslam
