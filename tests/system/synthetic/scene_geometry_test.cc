#include "system/synthetic/scene_geometry.h"

#include <gtest/gtest.h>

namespace cslam {
namespace {

TEST(SceneGeometry, BoxFacesPointOutwardOrInward) {
  const Pose pose = PoseFromVector((Vector6d() << 0.3, -0.2, 0.9, 1, 2, 3).finished());
  for (bool inward : {false, true}) {
    std::vector<SceneQuad> quads;
    AddBox(pose, {1.0, 2.0, 3.0}, Eigen::Vector3f::Ones(), 7, &quads, true, inward);
    ASSERT_EQ(quads.size(), 6u);
    double area = 0;
    for (const auto& q : quads) {
      const double side = q.Normal().dot(q.Center() - pose.translation());
      EXPECT_GT(inward ? -side : side, 0.0);
      EXPECT_NEAR(q.edge_u.dot(q.edge_v), 0.0, 1e-12);
      area += q.Area();
    }
    EXPECT_NEAR(area, 2 * (1 * 2 + 2 * 3 + 1 * 3), 1e-9);
  }
  std::vector<SceneQuad> open;
  AddBox(pose, {1, 1, 1}, Eigen::Vector3f::Ones(), 0, &open, false);
  EXPECT_EQ(open.size(), 5u);
}

TEST(SceneGeometry, SegmentCrossesARectangleOnlyInsideIt) {
  SceneQuad q;  // unit square in z = 0
  q.origin = {0, 0, 0};
  q.edge_u = {1, 0, 0};
  q.edge_v = {0, 1, 0};
  EXPECT_NEAR(IntersectSegment(q, {0.5, 0.5, -1}, {0.5, 0.5, 3}), 0.25, 1e-12);
  EXPECT_LT(IntersectSegment(q, {1.5, 0.5, -1}, {1.5, 0.5, 1}), 0);  // outside the edge
  EXPECT_LT(IntersectSegment(q, {0.5, 0.5, 1}, {0.5, 0.5, 2}), 0);   // does not reach it
  EXPECT_LT(IntersectSegment(q, {0.5, 0.5, 1}, {0.5, 0.5, 0}), 0);   // ends on it: no hit
  EXPECT_LT(IntersectSegment(q, {0, 0, 1}, {1, 1, 1}), 0);           // parallel
}

TEST(SceneGeometry, SegmentBlockedUsesTheBodyPoseOfTheFrame) {
  SceneGeometry g;
  g.bodies.resize(2);
  g.bodies[0].kind = "static";
  g.bodies[1].kind = "box";
  AddBox(Pose::Identity(), {1, 1, 1}, Eigen::Vector3f::Ones(), 0, &g.bodies[1].quads);
  std::vector<std::vector<Pose>> poses(2, std::vector<Pose>(2, Pose::Identity()));
  poses[1][0].translation() = Eigen::Vector3d(0, 0, 5);   // between camera and target
  poses[1][1].translation() = Eigen::Vector3d(10, 0, 5);  // moved aside
  EXPECT_TRUE(SegmentBlocked(g, poses, 0, {0, 0, 0}, {0, 0, 10}));
  EXPECT_FALSE(SegmentBlocked(g, poses, 1, {0, 0, 0}, {0, 0, 10}));
  // A point on the box's own near face is not blocked by that face.
  EXPECT_FALSE(SegmentBlocked(g, poses, 0, {0, 0, 0}, {0.1, 0.1, 4.5}));
  EXPECT_TRUE(SegmentBlocked(g, poses, 0, {0, 0, 0}, {0.1, 0.1, 5.5}));
}

}  // namespace
}  // namespace cslam
