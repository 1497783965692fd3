#include "system/map/co_location.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/system/map/car_points.h"

namespace cslam {
namespace {

Pose Translation(double x, double y, double z) {
  Pose p = Pose::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

using testing::CarPoints;

// Driving along z at 1 m per frame, `lateral` m to the side and `ahead` m ahead.
std::map<int, Pose> Drive(int begin, int end, double lateral, double ahead) {
  std::map<int, Pose> t;
  for (int f = begin; f < end; ++f) t[f] = Translation(lateral, 0, ahead + 1.0 * f);
  return t;
}

TEST(CoLocation, TwoPiecesOfOneBodyThatMoveApartAFewDecimetresShareOnePlace) {
  // A cyclist cut in two: the frame and the legs, which swing 0.3 m against it.
  const std::vector<Eigen::Vector3d> all = CarPoints(1);
  std::vector<Eigen::Vector3d> frame, legs;
  for (size_t i = 0; i < all.size(); ++i) (i % 2 ? legs : frame).push_back(all[i]);
  std::map<int, Pose> legs_motion = Drive(5, 30, 0, 10);
  for (auto& [f, pose] : legs_motion) pose = pose * Translation(0, 0.3 * std::sin(0.8 * f), 0);
  const CoLocation c = CompareLocations(Drive(0, 30, 0, 10), frame, legs_motion, legs);
  EXPECT_EQ(c.frames, 25);
  EXPECT_LT(c.median_ratio, 1.0);
}

TEST(CoLocation, TwoCarsSideBySideInNeighbouringLanesDoNot) {
  const CoLocation c =
      CompareLocations(Drive(0, 30, 0, 10), CarPoints(1), Drive(0, 30, 3.5, 10), CarPoints(2));
  EXPECT_EQ(c.frames, 30);
  EXPECT_GT(c.median_ratio, 1.5);
}

TEST(CoLocation, ACarFollowingAnotherTwoMetresBehindDoesNot) {
  const CoLocation c =
      CompareLocations(Drive(0, 30, 0, 10), CarPoints(1), Drive(0, 30, 0, 4), CarPoints(2));
  EXPECT_GT(c.median_ratio, 1.5);
}

TEST(CoLocation, NothingSharedIsNothingCompared) {
  EXPECT_EQ(CompareLocations(Drive(0, 10, 0, 10), CarPoints(1), Drive(10, 20, 0, 10), CarPoints(2)).frames, 0);
  EXPECT_EQ(CompareLocations(Drive(0, 10, 0, 10), {}, Drive(0, 10, 0, 10), CarPoints(2)).frames, 0);
}

}  // namespace
}  // namespace cslam
