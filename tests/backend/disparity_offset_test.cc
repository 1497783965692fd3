#include "backend/disparity_offset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/errors.h"
#include "tests/backend/test_scene.h"

namespace cslam {
namespace {

using testing::MakeScene;
using testing::RandomPoints;
using testing::SyntheticCamera;
using testing::TestScene;
using testing::YawPose;

// The camera drives forward 1 m a frame and turns a little, as on a road.
Pose DrivingCamera(int t) { return YawPose(0.01 * t, Eigen::Vector3d(0.1 * t, 0.0, 1.0 * t)); }

testing::TestBody StaticBody(int n, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, unsigned seed) {
  return {RandomPoints(n, lo, hi, seed), [](int) { return Pose::Identity(); }};
}

// A street: points from 4 m to 80 m ahead of the start, so disparities of 4–80 px and more
// (outdoor camera, fx 640, baseline 0.5 m) — near and far points together pin δ.
TestScene Street(double noise_px, unsigned seed) {
  return MakeScene(SyntheticCamera(true),
                   {StaticBody(600, {-15, -3, 4}, {15, 3, 80}, seed)}, 20, DrivingCamera,
                   noise_px, noise_px, seed + 1);
}

// Every right column moved by `shift` px: uR + shift, i.e. the disparity − shift; the δ that
// undoes it is +shift.
TrackletTable ShiftRight(const TrackletTable& table, double shift) {
  return CorrectDisparities(table, -shift);
}

// The motion the estimate starts from: the truth with its translation shrunk by 3 % (what a
// wrong offset does to a stereo odometry's scale) and a jitter.
std::vector<Pose> PerturbedMotion(const std::vector<Pose>& truth) {
  std::vector<Pose> out = truth;
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].translation() = 0.97 * truth[i].translation() +
                           0.02 * Eigen::Vector3d(std::sin(3.0 * i), std::cos(5.0 * i), 0.0);
    out[i].linear() = out[i].linear() * Eigen::AngleAxisd(0.002 * std::sin(7.0 * i),
                                                          Eigen::Vector3d::UnitX())
                                            .toRotationMatrix();
  }
  return out;
}

DisparityOffset Estimate(const TestScene& s, const TrackletTable& table) {
  const FrameRange range{0, table.num_frames()};
  return EstimateDisparityOffset(table, s.camera, range, PerturbedMotion(s.world_from_cam),
                                 DisparityOffsetOptions{});
}

TEST(EstimateDisparityOffset, RecoversAnOffsetInjectedIntoEveryRightColumn) {
  const TestScene s = Street(0.3, 11);
  for (double injected : {0.2, -0.15}) {
    const DisparityOffset d = Estimate(s, ShiftRight(s.table, injected));
    std::printf("injected %+.3f px: δ %+.4f ± %.4f px (%d landmarks, %d observations)\n",
                injected, d.offset_px, d.sigma_px, d.landmarks, d.observations);
    ASSERT_TRUE(d.usable) << d.reason;
    EXPECT_NEAR(d.offset_px, injected, 0.03);
    EXPECT_NEAR(d.offset_px, injected, 3.0 * d.sigma_px);
    // 0.3 px noise on ~10⁴ observations: δ is known to well under a hundredth of a pixel, and
    // σ says so; a σ of the order of δ would make the calibrator never apply it.
    EXPECT_LT(d.sigma_px, 0.02);
    EXPECT_GT(d.Significance(), 5.0);
  }
}

TEST(EstimateDisparityOffset, FindsNoOffsetWhereThereIsNone) {
  const TestScene s = Street(0.3, 21);
  const DisparityOffset d = Estimate(s, s.table);
  std::printf("no offset: δ %+.4f ± %.4f px\n", d.offset_px, d.sigma_px);
  ASSERT_TRUE(d.usable) << d.reason;
  EXPECT_NEAR(d.offset_px, 0.0, 0.03);
  EXPECT_LT(d.Significance(), 3.0);
}

TEST(EstimateDisparityOffset, MovingPointsDoNotBiasIt) {
  // A car a fifth of the landmarks, driving across the street at 1.5 m a frame.
  testing::TestBody car{RandomPoints(150, {-2, -1, 12}, {2, 1, 16}, 31),
               [](int t) { return Pose(Eigen::Translation3d(1.5 * t - 10.0, 0.0, 0.8 * t)); }};
  const TestScene s =
      MakeScene(SyntheticCamera(true), {StaticBody(600, {-15, -3, 4}, {15, 3, 80}, 32), car}, 20,
                DrivingCamera, 0.3, 0.3, 33);
  const DisparityOffset d = Estimate(s, ShiftRight(s.table, 0.2));
  std::printf("with a moving car: δ %+.4f ± %.4f px (%d landmarks kept)\n", d.offset_px,
              d.sigma_px, d.landmarks);
  ASSERT_TRUE(d.usable) << d.reason;
  EXPECT_NEAR(d.offset_px, 0.2, 0.03);
  // The car's points follow another motion and are left out: no more landmarks are kept
  // than static ones with a track long enough.
  int static_tracks = 0;
  for (int l = 0; l < s.table.num_landmarks(); ++l)
    static_tracks += s.truth[l] == 0 && s.table.ObservationsOf(l, {0, s.table.num_frames()}).size() >= 3;
  EXPECT_LE(d.landmarks, static_tracks);
}

TEST(EstimateDisparityOffset, SaysSoWhenOneDepthCannotTellItFromTheScale) {
  // A wall at 20 m seen while driving sideways along it: every disparity is 16 px in every
  // frame, so δ and the scale of the translation are one unknown; σ must say so.
  auto sideways = [](int t) { return Pose(Eigen::Translation3d(0.5 * t, 0.0, 0.0)); };
  const TestScene wall = MakeScene(SyntheticCamera(true),
                                   {StaticBody(200, {-15, -3, 20}, {25, 3, 20}, 41)}, 10,
                                   sideways, 0.3, 0.3, 42);
  const TestScene street = Street(0.3, 11);
  const DisparityOffset w = Estimate(wall, ShiftRight(wall.table, 0.2));
  const DisparityOffset d = Estimate(street, ShiftRight(street.table, 0.2));
  std::printf("wall: δ %+.4f ± %.4f px (usable %d); street σ %.4f px\n", w.offset_px, w.sigma_px,
              w.usable, d.sigma_px);
  // Either refused (|δ| beyond max_offset_px) or with a σ that keeps the calibrator off it.
  EXPECT_TRUE(!w.usable || w.sigma_px > 10.0 * d.sigma_px);
}

TEST(EstimateDisparityOffset, RefusesWithoutTwoFramesOfTracks) {
  const TestScene s = Street(0.3, 51);
  const TrackletTable one = s.table.Slice({0, 1});
  const DisparityOffset d = EstimateDisparityOffset(one, s.camera, {0, 1}, {s.world_from_cam[0]},
                                                    DisparityOffsetOptions{});
  EXPECT_FALSE(d.usable);
  EXPECT_FALSE(d.reason.empty());
  EXPECT_EQ(d.Significance(), 0.0);
}

TEST(CorrectDisparities, MovesOnlyTheRightColumnAndKeepsLandmarkIds) {
  TrackletTable t;
  t.Add(0, 0, Eigen::Vector3d(100, 50, 90), Eigen::Matrix3d::Identity());
  t.Add(2, 1, Eigen::Vector3d(200, 60, 180), 2.0 * Eigen::Matrix3d::Identity());
  const TrackletTable c = CorrectDisparities(t, 0.25);
  ASSERT_EQ(c.num_landmarks(), t.num_landmarks());
  ASSERT_EQ(c.num_frames(), t.num_frames());
  for (int f = 0; f < t.num_frames(); ++f) {
    const auto a = t.ObservationsAt(f), b = c.ObservationsAt(f);
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      const StereoObservation& o = t.Get(a[k]);
      const StereoObservation& p = c.Get(b[k]);
      EXPECT_EQ(p.landmark, o.landmark);
      EXPECT_EQ(p.x(0), o.x(0));
      EXPECT_EQ(p.x(1), o.x(1));
      EXPECT_DOUBLE_EQ(p.x(2), o.x(2) - 0.25);
      EXPECT_EQ(p.cov, o.cov);
    }
  }
}

TEST(DisparityOffsetOptions, CheckNamesTheBadKey) {
  DisparityOffsetOptions o;
  EXPECT_NO_THROW(o.Check());
  o.robust_kernel = "tukey";
  try {
    o.Check();
    FAIL() << "accepted robust_kernel tukey";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("robust_kernel"), std::string::npos);
  }
  o = {};
  o.min_track_length = 1;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.max_offset_px = 0;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam
