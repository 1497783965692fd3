#include "system/map/map_state.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "core/errors.h"
#include "system/map/object_report.h"
#include "tests/support/matchers.h"
#include "tests/support/random.h"

namespace cslam {
namespace {

// A ground-truth world: a camera driving forward and turning slowly, two objects with their
// own motions, static landmarks and object landmarks fixed in their bodies.
struct World {
  std::vector<Pose> world_from_cam;
  std::vector<std::vector<Pose>> world_from_object;  // [object 1..2 → index 0..1][frame]
  std::vector<int> label;                            // 0 static, 1 or 2
  std::vector<Eigen::Vector3d> p_in_object;          // world frame for static ones
};

Pose MakePose(double yaw, double x, double y, double z) {
  Vector6d xi;
  xi << 0, yaw, 0, x, y, z;
  return PoseFromVector(xi);
}

World MakeWorld(int frames) {
  World w;
  for (int f = 0; f < frames; ++f) w.world_from_cam.push_back(MakePose(0.01 * f, 0.05 * f, 0, 1.0 * f));
  w.world_from_object.resize(2);
  for (int f = 0; f < frames; ++f) {
    w.world_from_object[0].push_back(MakePose(0.02 * f, 3 + 0.1 * f, 0, 10 + 1.5 * f));
    w.world_from_object[1].push_back(MakePose(-0.03 * f, -4 + 0.3 * f, 0, 20 - 0.5 * f));
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 60; ++i) {
    w.label.push_back(i < 30 ? 0 : (i < 45 ? 1 : 2));
    const Eigen::Vector3d d = testing::Draw3([&] { return u(rng); });
    w.p_in_object.emplace_back(d.x() * (i < 30 ? 10 : 1), d.y(), d.z() * (i < 30 ? 10 : 2) + (i < 30 ? 30 : 0));
  }
  return w;
}

// What a perfect backend returns for a window: world = camera at range.begin, each cluster's
// frame = an arbitrary per-window offset of the true body frame, labels permuted per window.
MotionEstimate PerfectWindow(const World& w, FrameRange range, const std::map<int, int>& relabel) {
  MotionEstimate e;
  e.range = range;
  const Pose window_from_world = w.world_from_cam[range.begin].inverse();
  for (int f = range.begin; f < range.end; ++f)
    e.world_from_cam.push_back(window_from_world * w.world_from_cam[f]);
  e.landmark_cluster.assign(w.label.size(), -1);
  e.landmark_in_cluster.assign(w.label.size(), Eigen::Vector3d::Constant(NAN));
  std::vector<Pose> offset(3);
  for (int obj = 1; obj <= 2; ++obj) offset[obj] = MakePose(0.3 * obj + 0.01 * range.begin, obj, -obj, 0.5);
  for (size_t l = 0; l < w.label.size(); ++l) {
    const int obj = w.label[l];
    e.landmark_cluster[l] = obj == 0 ? 0 : relabel.at(obj);
    e.landmark_in_cluster[l] =
        obj == 0 ? Eigen::Vector3d(window_from_world * w.p_in_object[l])
                 : Eigen::Vector3d(offset[obj].inverse() * w.p_in_object[l]);
  }
  for (int obj = 1; obj <= 2; ++obj) {
    ClusterMotion m;
    m.cluster = relabel.at(obj);
    for (int f = range.begin; f < range.end; ++f) {
      m.frames.push_back(f);
      const Pose world_from_cluster = window_from_world * w.world_from_object[obj - 1][f] * offset[obj];
      m.world_from_cluster.push_back(world_from_cluster);
      m.cam_from_cluster.push_back(e.world_from_cam[f - range.begin].inverse() * world_from_cluster);
    }
    e.clusters.push_back(m);
  }
  std::sort(e.clusters.begin(), e.clusters.end(),
            [](const ClusterMotion& a, const ClusterMotion& b) { return a.cluster < b.cluster; });
  return e;
}

TEST(MapState, StitchesPerfectWindowsIntoTheTrueTrajectories) {
  const World w = MakeWorld(60);
  MapState map;
  int k = 0;
  for (int begin = 0; begin + 30 <= 60; begin += 5, ++k) {
    // Window labels swap every other window: the map ids must not.
    const std::map<int, int> relabel = (k % 2) ? std::map<int, int>{{1, 2}, {2, 1}}
                                               : std::map<int, int>{{1, 1}, {2, 2}};
    const WindowIntegration info = map.Integrate(PerfectWindow(w, {begin, begin + 30}, relabel));
    if (k == 0) {
      EXPECT_EQ(info.created, 2);
    } else {
      EXPECT_EQ(info.created, 0);
      EXPECT_EQ(info.associated, 2);
      EXPECT_FALSE(info.gap);
    }
  }
  ASSERT_EQ(map.num_frames(), 60);
  for (int f = 0; f < 60; ++f) {
    ASSERT_TRUE(map.world_from_cam()[f].has_value());
    EXPECT_TRUE(testing::PoseNear(*map.world_from_cam()[f], w.world_from_cam[f], 1e-9, 1e-9)) << f;
  }
  ASSERT_EQ(map.clusters().size(), 2u);
  // Each map cluster follows one true object up to a constant body-frame offset.
  for (const auto& [id, cluster] : map.clusters()) {
    ASSERT_EQ(cluster.world_from_cluster.size(), 60u);
    const int landmark = id == 1 ? 30 : 45;  // window 0 labelled object 1 → id 1
    const int obj = w.label[landmark];
    const Pose offset = w.world_from_object[obj - 1][0].inverse() * cluster.world_from_cluster.at(0);
    for (const auto& [f, pose] : cluster.world_from_cluster)
      EXPECT_TRUE(testing::PoseNear(pose, w.world_from_object[obj - 1][f] * offset, 1e-9, 1e-9));
  }
  for (size_t l = 0; l < w.label.size(); ++l) {
    const auto p = map.WorldPosition(static_cast<int>(l), 42);
    ASSERT_TRUE(p.has_value());
    const Eigen::Vector3d truth = w.label[l] == 0 ? w.p_in_object[l]
                                                  : w.world_from_object[w.label[l] - 1][42] * w.p_in_object[l];
    EXPECT_TRUE(testing::MatrixNear(*p, truth, 1e-9));
  }
  EXPECT_EQ(map.ClusterOf(30), map.ClusterOf(44));
  EXPECT_NE(map.ClusterOf(30), map.ClusterOf(45));
  EXPECT_EQ(map.ClusterOf(0), 0);
  // Windows 0..29, 5..34, …, 30..59: every one found both objects.
  EXPECT_EQ(map.WindowsCovering(0, 59), 7);
  EXPECT_EQ(map.WindowsCovering(0, 4), 1);
  EXPECT_EQ(map.WindowsCovering(29, 30), 7);
  EXPECT_EQ(map.WindowsCovering(59, 70), 1);
  for (const auto& [id, cluster] : map.clusters()) EXPECT_EQ(cluster.windows, 7) << id;
}

// Gives the landmarks of `object` new ids in `e` (appended at the end), as a frontend does
// when it loses an object's tracks and finds them again: the map cannot know they are the same.
// Returns the new ids.
std::vector<int> Reidentify(const World& w, int object, MotionEstimate* e) {
  std::vector<int> fresh;
  const size_t n = w.label.size();
  for (size_t l = 0; l < n; ++l) {
    if (w.label[l] != object) continue;
    fresh.push_back(static_cast<int>(e->landmark_cluster.size()));
    e->landmark_cluster.push_back(e->landmark_cluster[l]);
    e->landmark_in_cluster.push_back(e->landmark_in_cluster[l]);
    e->landmark_cluster[l] = -1;
  }
  return fresh;
}

// Expects map cluster `id` to follow true object `obj` up to a constant body-frame offset.
void ExpectFollows(const World& w, const MapState& map, int id, int obj) {
  const MapCluster& c = map.clusters().at(id);
  const Pose offset = w.world_from_object[obj - 1][c.world_from_cluster.begin()->first].inverse() *
                      c.world_from_cluster.begin()->second;
  for (const auto& [f, pose] : c.world_from_cluster)
    EXPECT_TRUE(testing::PoseNear(pose, w.world_from_object[obj - 1][f] * offset, 1e-6, 1e-6))
        << "cluster " << id << " frame " << f;
}

TEST(MapState, AClusterWithTooLittleOverlapStartsANewIdWhenMergingIsOff) {
  const World w = MakeWorld(40);
  MapStateOptions o;
  o.merge_agreeing_clusters = false;
  MapState map(o);
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  // Second window: object 1's landmarks are re-identified under new ids (a new track set).
  MotionEstimate e = PerfectWindow(w, {5, 35}, {{1, 1}, {2, 2}});
  const size_t n = e.landmark_cluster.size();
  for (size_t l = 0; l < n; ++l) {
    if (w.label[l] != 1) continue;
    e.landmark_cluster.push_back(e.landmark_cluster[l]);
    e.landmark_in_cluster.push_back(e.landmark_in_cluster[l]);
    e.landmark_cluster[l] = -1;
  }
  const WindowIntegration info = map.Integrate(e);
  EXPECT_EQ(info.created, 1);
  EXPECT_EQ(info.associated, 1);
  EXPECT_EQ(map.clusters().size(), 3u);
}

TEST(MapState, AnObjectSplitIntoTwoMapClustersIsMergedUnderTheOlderId) {
  const World w = MakeWorld(40);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  // Object 1 comes back under new landmark ids: no landmark ties it to map cluster 1, so the
  // window starts a new cluster; its motion then matches cluster 1's over 25 frames.
  MotionEstimate e = PerfectWindow(w, {5, 35}, {{1, 2}, {2, 1}});
  const std::vector<int> fresh = Reidentify(w, 1, &e);
  const WindowIntegration info = map.Integrate(e);
  EXPECT_EQ(info.created, 1);
  ASSERT_EQ(info.merged.size(), 1u);
  EXPECT_EQ(info.merged[0], (std::pair<int, int>{1, 3}));
  ASSERT_EQ(map.clusters().size(), 2u);
  EXPECT_EQ(map.ClusterOf(30), 1);
  for (int l : fresh) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  EXPECT_EQ(map.clusters().at(1).num_landmarks, 30);  // the old 15 and their 15 new ids
  EXPECT_EQ(map.clusters().at(1).windows, 2);         // each piece was found once
  ASSERT_EQ(map.clusters().at(1).world_from_cluster.size(), 35u);
  ExpectFollows(w, map, 1, 1);
  ExpectFollows(w, map, 2, 2);
  for (int l : fresh) {
    const auto p = map.WorldPosition(l, 33);
    ASSERT_TRUE(p.has_value());
    const int original = static_cast<int>(l - w.label.size() + 30);  // object 1 = ids 30..44
    EXPECT_TRUE(testing::MatrixNear(*p, w.world_from_object[0][33] * w.p_in_object[original], 1e-6));
  }
}

// A second car driving exactly as object 1 does, 12 m from it: one motion, two places with
// nothing between them. The motion test alone merges them; the place keeps them apart.
TEST(MapState, TwoBodiesOfOneMotionMetresApartAreNotMerged) {
  const World w = MakeWorld(40);
  for (double gap : {0.0, 4.0}) {
    MapStateOptions o;
    o.split_gap_m = gap;
    MapState map(o);
    map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
    MotionEstimate e = PerfectWindow(w, {5, 35}, {{1, 2}, {2, 1}});
    const std::vector<int> fresh = Reidentify(w, 1, &e);
    for (int l : fresh) e.landmark_in_cluster[l] += Eigen::Vector3d(12, 0, 0);
    const WindowIntegration info = map.Integrate(e);
    if (gap == 0) {
      EXPECT_EQ(info.merged.size(), 1u);
      EXPECT_EQ(map.ClusterOf(fresh[0]), 1);
    } else {
      EXPECT_TRUE(info.merged.empty());
      EXPECT_NE(map.ClusterOf(fresh[0]), 1);
      EXPECT_GE(map.ClusterOf(fresh[0]), 1);
      ExpectFollows(w, map, 1, 1);
    }
  }
}

// Object 1 comes back as a window cluster of only `kept` new landmarks, its motion perfect.
struct Fragment {
  MapState map;
  WindowIntegration info;
  std::vector<int> fresh;
};
Fragment ObjectReturnsWith(const World& w, size_t kept) {
  Fragment f;
  f.map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  MotionEstimate e = PerfectWindow(w, {5, 35}, {{1, 1}, {2, 2}});
  f.fresh = Reidentify(w, 1, &e);
  for (size_t k = kept; k < f.fresh.size(); ++k) {
    e.landmark_cluster[f.fresh[k]] = -1;
    e.landmark_in_cluster[f.fresh[k]] = Eigen::Vector3d::Constant(NAN);
  }
  f.info = f.map.Integrate(e);
  return f;
}

TEST(MapState, AClusterOfTwoLandmarksIsNotMergedByItsMotion) {
  const World w = MakeWorld(40);
  // Its motion agrees with cluster 1's, but 2 points do not fix a rigid body's pose, so the
  // map does not let it extend the object's trajectory.
  const Fragment two = ObjectReturnsWith(w, 2);
  EXPECT_EQ(two.info.created, 1);
  EXPECT_TRUE(two.info.merged.empty());
  EXPECT_NE(two.map.ClusterOf(two.fresh[0]), 1);
  EXPECT_EQ(two.map.ClusterOf(two.fresh[0]), two.map.ClusterOf(two.fresh[1]));
  // With 3 of them it is merged, as a fragment of the object.
  const Fragment three = ObjectReturnsWith(w, 3);
  ASSERT_EQ(three.info.merged.size(), 1u);
  EXPECT_EQ(three.map.ClusterOf(three.fresh[0]), 1);
}

TEST(MapState, TwoObjectsWithDifferentMotionsAreNeverMerged) {
  const World w = MakeWorld(60);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  // Both objects come back under new ids in every later window: each new cluster may only
  // join the map cluster of its own object.
  for (int begin = 5; begin + 30 <= 60; begin += 5) {
    MotionEstimate e = PerfectWindow(w, {begin, begin + 30}, {{1, 1}, {2, 2}});
    Reidentify(w, 1, &e);
    Reidentify(w, 2, &e);
    const WindowIntegration info = map.Integrate(e);
    for (const auto& [older, younger] : info.merged) EXPECT_NE(older, 0) << "a moving object went static";
  }
  ASSERT_EQ(map.clusters().size(), 2u);
  EXPECT_NE(map.ClusterOf(30), map.ClusterOf(45));
  ExpectFollows(w, map, map.ClusterOf(30), 1);
  ExpectFollows(w, map, map.ClusterOf(45), 2);
}

TEST(MapState, AFewMislabelledLandmarksDoNotTieAnObjectToAnotherCluster) {
  const World w = MakeWorld(40);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  // Object 2 comes back under new ids, and the window wrongly puts four of object 1's
  // landmarks into object 2's cluster: the only landmarks of that window cluster the map
  // knows are cluster 1's.
  MotionEstimate e = PerfectWindow(w, {5, 35}, {{1, 1}, {2, 2}});
  const std::vector<int> fresh = Reidentify(w, 2, &e);
  for (int l = 30; l < 34; ++l) e.landmark_cluster[l] = 2;
  const WindowIntegration info = map.Integrate(e);
  EXPECT_EQ(info.created, 1);  // object 2's window cluster did not continue cluster 1
  ASSERT_EQ(map.clusters().size(), 2u);
  EXPECT_EQ(map.ClusterOf(40), 1);
  for (int l : fresh) EXPECT_EQ(map.ClusterOf(l), 2) << l;  // merged into object 2's old id
  ExpectFollows(w, map, 1, 1);
  ExpectFollows(w, map, 2, 2);
}

TEST(MapState, AClusterThatHoldsStillFoldsIntoTheStaticWorld) {
  const World w = MakeWorld(40);
  MapState map;
  // The window wrongly calls ten static landmarks a moving cluster (label 3, not moving).
  MotionEstimate e = PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}});
  ClusterMotion still;
  still.cluster = 3;
  for (int f = 0; f < 30; ++f) {
    still.frames.push_back(f);
    still.world_from_cluster.push_back(Pose::Identity());
    still.cam_from_cluster.push_back(e.world_from_cam[f].inverse());
  }
  e.clusters.push_back(still);
  for (int l = 0; l < 10; ++l) e.landmark_cluster[l] = 3;
  const WindowIntegration info = map.Integrate(e);
  EXPECT_EQ(info.created, 3);
  ASSERT_EQ(info.merged.size(), 1u);
  EXPECT_EQ(info.merged[0], (std::pair<int, int>{0, 3}));
  EXPECT_EQ(map.clusters().size(), 2u);
  for (int l = 0; l < 10; ++l) {
    EXPECT_EQ(map.ClusterOf(l), 0);
    EXPECT_TRUE(testing::MatrixNear(*map.WorldPosition(l, 20), w.p_in_object[l], 1e-6));
  }
}

// A window that sees object 2's landmarks (ids 45..59) but cannot tell that they move (the
// car is far and drives along the line of sight): it labels them static, as fixed points where
// the camera saw them at the window's first frame, and reports no cluster for object 2.
// `moving_too`: it still finds object 2 moving in all but those of `lost`.
MotionEstimate WindowLosingObject2(const World& w, FrameRange range, const std::vector<int>& lost,
                                   bool moving_too) {
  MotionEstimate e = PerfectWindow(w, range, {{1, 1}, {2, 2}});
  if (!moving_too) std::erase_if(e.clusters, [](const ClusterMotion& m) { return m.cluster == 2; });
  const Pose window_from_world = w.world_from_cam[range.begin].inverse();
  for (int l : lost) {
    e.landmark_cluster[l] = 0;
    e.landmark_in_cluster[l] = window_from_world * w.world_from_object[1][range.begin] * w.p_in_object[l];
  }
  return e;
}

TEST(MapState, AWindowThatLosesAMovingBodyLeavesItsLandmarksWithTheBody) {
  const World w = MakeWorld(40);
  std::vector<int> object2;
  for (int l = 45; l < 60; ++l) object2.push_back(l);
  for (const bool keep : {true, false}) {
    MapStateOptions options;
    options.keep_lost_members = keep;
    MapState map(options);
    map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
    map.Integrate(WindowLosingObject2(w, {5, 35}, object2, false));
    for (int l : object2) EXPECT_EQ(map.ClusterOf(l), keep ? 2 : 0) << l << (keep ? "" : " (off)");
    if (keep) ExpectFollows(w, map, 2, 2);
  }
}

TEST(MapState, LandmarksAWindowSeesStayBehindTheirMovingBodyJoinTheStaticWorld) {
  const World w = MakeWorld(40);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  // The window finds object 2 moving in ten of its landmarks; the other five it labels static.
  map.Integrate(WindowLosingObject2(w, {5, 35}, {45, 46, 47, 48, 49}, true));
  for (int l = 45; l < 50; ++l) EXPECT_EQ(map.ClusterOf(l), 0) << l;
  for (int l = 50; l < 60; ++l) EXPECT_EQ(map.ClusterOf(l), 2) << l;
}

// Object 1 as a body that is not rigid: its odd landmarks (the legs of a cyclist) swing
// `swing_m` up and down against the rest. A window that clusters the two parts apart reports
// them as clusters 1 and 3.
MotionEstimate SwingingWindow(const World& w, FrameRange range, double swing_m) {
  MotionEstimate e = PerfectWindow(w, range, {{1, 1}, {2, 2}});
  const ClusterMotion body = *e.FindCluster(1);
  ClusterMotion legs;
  legs.cluster = 3;
  for (size_t k = 0; k < body.frames.size(); ++k) {
    const int f = body.frames[k];
    Pose swing = Pose::Identity();
    swing.translation().y() = swing_m * std::sin(0.8 * f);
    legs.frames.push_back(f);
    legs.world_from_cluster.push_back(body.world_from_cluster[k] * swing);
    legs.cam_from_cluster.push_back(body.cam_from_cluster[k] * swing);
  }
  e.clusters.push_back(legs);
  for (size_t l = 0; l < w.label.size(); ++l)
    if (w.label[l] == 1 && l % 2) e.landmark_cluster[l] = 3;
  return e;
}

TEST(MapState, TwoPartsOfOneBodyThatIsNotRigidAreMergedBecauseTheyShareOnePlace) {
  const World w = MakeWorld(40);
  // 0.5 m of swing is more than the rigid motion test tolerates at these ranges.
  MapStateOptions rigid_only;
  rigid_only.co_location_ratio = 0;
  MapState apart(rigid_only);
  apart.Integrate(SwingingWindow(w, {0, 30}, 0.5));
  EXPECT_EQ(apart.clusters().size(), 3u);
  EXPECT_NE(apart.ClusterOf(30), apart.ClusterOf(31));

  MapState map;
  const WindowIntegration info = map.Integrate(SwingingWindow(w, {0, 30}, 0.5));
  ASSERT_EQ(info.merged.size(), 1u);
  EXPECT_EQ(info.merged[0], (std::pair<int, int>{1, 3}));
  ASSERT_EQ(map.clusters().size(), 2u);
  for (int l = 30; l < 45; ++l) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  EXPECT_EQ(map.ClusterOf(45), 2);  // object 2, elsewhere, stays apart
  ExpectFollows(w, map, 1, 1);
}

// The windows put half of object 1's points in a cluster of their own, placed metres off and
// swinging (a far car's pieces on the windows' poses): neither one motion nor one place, so the
// map keeps them apart over all 30 shared frames. Once the end of the run has tracked the piece
// where its points are, the two move as one rigid body and are merged; left swinging, not.
TEST(MapState, PiecesSharingManyFramesAreMergedAtTheEndOnceTheirTracksMoveAsOne) {
  const World w = MakeWorld(40);
  MapState map;
  map.Integrate(SwingingWindow(w, {0, 30}, 6.0));
  ASSERT_EQ(map.clusters().size(), 3u);
  const int piece = map.ClusterOf(31);
  ASSERT_NE(piece, map.ClusterOf(30));
  ASSERT_EQ(map.ClusterOf(30), 1);
  EXPECT_TRUE(map.MergeCoLocatedClusters().empty());  // swinging: not one rigid motion

  map.SetTrajectory(piece, map.clusters().at(1).world_from_cluster);  // tracked: rigid
  const std::vector<std::pair<int, int>> merged = map.MergeCoLocatedClusters();
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_EQ(merged[0], (std::pair<int, int>{1, piece}));
  for (int l = 30; l < 45; ++l) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  EXPECT_EQ(map.ClusterOf(45), 2);  // object 2 moves otherwise
  ExpectFollows(w, map, 1, 1);
}

// The same pieces, the piece tracked with a few decimetres of noise per frame (a far car's
// track): more than the relative motion tolerance allows at these ranges, well within what two
// tracks each known to 0.25 m explain, not within 0.05 m. Object 2, elsewhere and moving
// otherwise, stays apart however large the tracks' errors.
int MergesOfANoisyPiece(double sigma_m) {
  const World w = MakeWorld(40);
  MapState map;
  map.Integrate(SwingingWindow(w, {0, 30}, 6.0));
  const int piece = map.ClusterOf(31);
  std::map<int, Pose> noisy = map.clusters().at(1).world_from_cluster;
  for (auto& [f, pose] : noisy)
    pose.translation() += 0.3 * Eigen::Vector3d(std::sin(1.7 * f), std::cos(2.3 * f), std::sin(0.9 * f));
  map.SetTrajectory(piece, noisy);
  const std::vector<std::pair<int, int>> merged =
      map.MergeCoLocatedClusters([sigma_m](int) { return sigma_m; });
  EXPECT_EQ(map.ClusterOf(45), 2);
  for (const auto& [kept, gone] : merged) EXPECT_EQ(kept, 1) << gone;
  return static_cast<int>(merged.size());
}

TEST(MapState, PiecesWhoseTracksDifferByNoMoreThanTheirErrorsAreMergedAtTheEnd) {
  EXPECT_EQ(MergesOfANoisyPiece(0), 0);  // the tracks' errors unknown: the relative tolerance
  EXPECT_EQ(MergesOfANoisyPiece(0.05), 0);
  EXPECT_EQ(MergesOfANoisyPiece(0.25), 1);
  EXPECT_EQ(MergesOfANoisyPiece(5.0), 1);  // object 2 still apart
}

// The same pieces with a report floor of 8 landmarks: the piece (7) is too small to be reported
// alone, object 1's other part (8) is not. The end-of-run merge runs before the floor and the
// piece is reported with its object; two parts that each fall short (floor 10) are released
// even once joined: fragments that only found each other are no established body.
int ReleasedAfterTheEndOfRunMerge(int report_min_landmarks, std::set<int>* reported) {
  const World w = MakeWorld(40);
  MapStateOptions o;
  o.report_min_landmarks = report_min_landmarks;
  MapState map(o);
  map.Integrate(SwingingWindow(w, {0, 30}, 6.0));
  const int piece = map.ClusterOf(31);
  EXPECT_NE(piece, map.ClusterOf(30));
  const std::set<int> landmarks = ReportedLandmarks(map, o);
  EXPECT_FALSE(landmarks.count(31));
  map.SetTrajectory(piece, map.clusters().at(1).world_from_cluster);
  EXPECT_EQ(map.MergeCoLocatedClusters().size(), 1u);
  EXPECT_TRUE(ReportedClusters(map, o).count(1));  // joined, 15 landmarks pass either floor
  const int released = KeepClustersHolding(&map, landmarks);
  for (const auto& [id, c] : map.clusters()) reported->insert(id);
  for (int l = 30; l < 45; ++l) EXPECT_EQ(map.ClusterOf(l), reported->count(1) ? 1 : -1) << l;
  return released;
}

TEST(MapState, APieceTooSmallToReportAloneIsReportedWithTheObjectItJoinsAtTheEnd) {
  std::set<int> reported;
  EXPECT_EQ(ReleasedAfterTheEndOfRunMerge(8, &reported), 0);
  EXPECT_EQ(reported, std::set<int>({1, 2}));
  reported.clear();
  EXPECT_EQ(ReleasedAfterTheEndOfRunMerge(10, &reported), 1);
  EXPECT_EQ(reported, std::set<int>({2}));
}

// Object 1's tracks all turn over as a new window begins: the next window finds it under new
// landmark ids, sharing only 3 frames with the map cluster, too few to compare motions.
int ClustersAfterAHandOver(int co_location_min_frames) {
  const World w = MakeWorld(60);
  MapStateOptions o;
  o.co_location_min_frames = co_location_min_frames;
  MapState map(o);
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  MotionEstimate e = PerfectWindow(w, {27, 57}, {{1, 1}, {2, 2}});
  const std::vector<int> fresh = Reidentify(w, 1, &e);
  map.Integrate(e);
  EXPECT_EQ(map.ClusterOf(fresh[0]), map.ClusterOf(fresh[1]));
  if (map.ClusterOf(fresh[0]) == 1) ExpectFollows(w, map, 1, 1);
  return static_cast<int>(map.clusters().size());
}

TEST(MapState, ABodyHandedOverBetweenWindowsInAFewFramesIsMergedByPlace) {
  EXPECT_EQ(ClustersAfterAHandOver(2), 2);  // objects 1 and 2
  EXPECT_EQ(ClustersAfterAHandOver(3), 2);
  EXPECT_EQ(ClustersAfterAHandOver(4), 3);  // more shared frames asked for than there are
}

// The same hand-over, but the second window places object 1 five metres off (a far car's
// window poses): the place test cannot merge the two clusters then. Once the end of the run has
// tracked both where they are, it can; object 2, elsewhere, stays apart.
TEST(MapState, AHandOverTheWindowsPlacedApartIsMergedOnceTheTracksAgreeOnItsPlace) {
  const World w = MakeWorld(60);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  MotionEstimate e = PerfectWindow(w, {27, 57}, {{1, 1}, {2, 2}});
  const std::vector<int> fresh = Reidentify(w, 1, &e);
  Pose shift = Pose::Identity();
  shift.translation() = Eigen::Vector3d(5, 0, 0);
  for (ClusterMotion& m : e.clusters) {
    if (m.cluster != 1) continue;
    for (size_t k = 0; k < m.frames.size(); ++k) {
      m.world_from_cluster[k] = shift * m.world_from_cluster[k];
      m.cam_from_cluster[k] = e.world_from_cam[m.frames[k] - 27].inverse() * m.world_from_cluster[k];
    }
  }
  map.Integrate(e);
  const int handed = map.ClusterOf(fresh[0]);
  ASSERT_EQ(map.clusters().size(), 3u);
  ASSERT_NE(handed, 1);
  EXPECT_TRUE(map.MergeCoLocatedClusters().empty());  // still five metres off

  // The second window's world is the camera at frame 27, the map's the camera at frame 0.
  const Pose map_from_window = w.world_from_cam[0].inverse() * w.world_from_cam[27];
  const Pose unshift = map_from_window * shift.inverse() * map_from_window.inverse();
  std::map<int, Pose> tracked;
  for (const auto& [f, pose] : map.clusters().at(handed).world_from_cluster) tracked[f] = unshift * pose;
  map.SetTrajectory(handed, tracked);
  const std::vector<std::pair<int, int>> merged = map.MergeCoLocatedClusters();
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_EQ(merged[0], (std::pair<int, int>{1, handed}));
  ASSERT_EQ(map.clusters().size(), 2u);
  for (int l : fresh) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  EXPECT_EQ(map.ClusterOf(45), 2);
  ExpectFollows(w, map, 1, 1);  // one body over all 57 frames
  for (int l : fresh)  // the handed-over points land where the body carries them
    EXPECT_LT((*map.WorldPosition(l, 50) - w.world_from_object[0][50] * w.p_in_object[30 + (l - fresh[0])]).norm(), 1e-6);
}

// Object 1 is hidden from frame 30 to 49 (behind a parked van): the window over 25..54 does
// not see it, and the one over 50..79 finds it on new tracks, sharing no frame with the map.
int ClustersAfterAnOcclusion(double reappearance_max_gap_s, std::vector<int>* fresh,
                             MapState* out) {
  const World w = MakeWorld(80);
  MapStateOptions o;
  o.reappearance_max_gap_s = reappearance_max_gap_s;
  MapState map(o);
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  MotionEstimate hidden = PerfectWindow(w, {25, 55}, {{1, 1}, {2, 2}});
  for (size_t l = 0; l < w.label.size(); ++l)
    if (w.label[l] == 1) hidden.landmark_cluster[l] = -1;
  std::erase_if(hidden.clusters, [](const ClusterMotion& m) { return m.cluster == 1; });
  map.Integrate(hidden);
  MotionEstimate back = PerfectWindow(w, {50, 80}, {{1, 1}, {2, 2}});
  *fresh = Reidentify(w, 1, &back);
  map.Integrate(back);
  *out = map;
  return static_cast<int>(map.clusters().size());
}

TEST(MapState, AnObjectBackFromBehindAnOccluderKeepsItsIdAndItsPointsLandWhereTheyAre) {
  const World w = MakeWorld(80);
  std::vector<int> fresh;
  MapState map;
  ASSERT_EQ(ClustersAfterAnOcclusion(3.0, &fresh, &map), 2);
  for (int l : fresh) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  const MapCluster& c = map.clusters().at(1);
  EXPECT_EQ(c.world_from_cluster.begin()->first, 0);
  EXPECT_EQ(c.world_from_cluster.rbegin()->first, 79);
  EXPECT_EQ(c.world_from_cluster.count(40), 0u);  // nothing is made up for the hidden frames
  for (int l : fresh) {
    const int original = static_cast<int>(l - w.label.size() + 30);  // object 1 = ids 30..44
    for (int f : {50, 79}) {
      const auto p = map.WorldPosition(l, f);
      ASSERT_TRUE(p.has_value());
      EXPECT_TRUE(testing::MatrixNear(*p, w.world_from_object[0][f] * w.p_in_object[original], 1e-6))
          << l << " at " << f;
    }
    // ... and the old landmarks, carried by the new poses, where they truly are.
    const auto old = map.WorldPosition(original, 60);
    ASSERT_TRUE(old.has_value());
    EXPECT_LT((*old - w.world_from_object[0][60] * w.p_in_object[original]).norm(), 0.05) << original;
  }
}

TEST(MapState, AnObjectBackFromBehindAnOccluderIsANewOneWhenReappearanceIsOff) {
  std::vector<int> fresh;
  MapState map;
  EXPECT_EQ(ClustersAfterAnOcclusion(0, &fresh, &map), 3);
  EXPECT_EQ(map.ClusterOf(fresh[0]), 3);
}

// Object 1's tracks all end at frame 29 and the next window, 25..54, finds it on new tracks
// from frame 33 on (a far car the windows lost for a few frames): no frame shared, so only the
// end-of-run join across the gap makes it one object again.
MapState AfterAFourFrameGap(std::vector<int>* fresh) {
  const World w = MakeWorld(55);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  MotionEstimate back = PerfectWindow(w, {25, 55}, {{1, 1}, {2, 2}});
  *fresh = Reidentify(w, 1, &back);
  ClusterMotion& m = back.clusters[0];
  const size_t lost = 33 - 25;
  m.frames.erase(m.frames.begin(), m.frames.begin() + lost);
  m.world_from_cluster.erase(m.world_from_cluster.begin(), m.world_from_cluster.begin() + lost);
  m.cam_from_cluster.erase(m.cam_from_cluster.begin(), m.cam_from_cluster.begin() + lost);
  map.Integrate(back);
  return map;
}

ReappearanceGate JoinGate(double max_gap_s) {
  ReappearanceGate gate;
  gate.frame_period_s = 0.1;
  gate.max_gap_s = max_gap_s;
  return gate;
}

TEST(MapState, APieceBackAfterAFewFramesIsJoinedToItsBodyAtTheEnd) {
  const World w = MakeWorld(55);
  std::vector<int> fresh;
  MapState map = AfterAFourFrameGap(&fresh);
  ASSERT_EQ(map.clusters().size(), 3u);
  const int piece = map.ClusterOf(fresh[0]);
  ASSERT_NE(piece, 1);
  const std::vector<std::pair<int, int>> merged = map.MergeReappearedClusters(JoinGate(0.5));
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_EQ(merged[0], (std::pair<int, int>{1, piece}));
  ASSERT_EQ(map.clusters().size(), 2u);
  for (int l : fresh) EXPECT_EQ(map.ClusterOf(l), 1) << l;
  EXPECT_EQ(map.ClusterOf(45), 2);  // object 2 is elsewhere all along
  const MapCluster& c = map.clusters().at(1);
  EXPECT_EQ(c.world_from_cluster.begin()->first, 0);
  EXPECT_EQ(c.world_from_cluster.rbegin()->first, 54);
  EXPECT_EQ(c.world_from_cluster.count(31), 0u);  // nothing is made up for the gap
  for (int l : fresh) {  // the piece's points land where the body carries them
    const int original = static_cast<int>(l - w.label.size() + 30);
    const auto p = map.WorldPosition(l, 50);
    ASSERT_TRUE(p.has_value());
    EXPECT_LT((*p - w.world_from_object[0][50] * w.p_in_object[original]).norm(), 1e-6) << l;
  }
}

TEST(MapState, APieceBackAfterALongerGapThanTheJoinBridgesStaysApart) {
  std::vector<int> fresh;
  MapState map = AfterAFourFrameGap(&fresh);
  EXPECT_TRUE(map.MergeReappearedClusters(JoinGate(0.3)).empty());
  EXPECT_TRUE(map.MergeReappearedClusters(JoinGate(0)).empty());
  EXPECT_EQ(map.clusters().size(), 3u);
}

TEST(MapState, OptionsRejectANegativeReappearanceGapOrAcceleration) {
  MapStateOptions o;
  o.reappearance_max_gap_s = -1;
  EXPECT_THROW(o.Check(), ConfigError);
  o.reappearance_max_gap_s = 0;
  EXPECT_NO_THROW(o.Check());
  o.reappearance_max_acceleration_mps2 = -0.5;
  EXPECT_THROW(o.Check(), ConfigError);
  o.reappearance_max_acceleration_mps2 = 3;
  o.frame_period_s = 0;
  EXPECT_THROW(o.Check(), ConfigError);
}

TEST(MapState, ACompactWindowIntegratesAsTheSameWindowNumberedByMapIds) {
  const World w = MakeWorld(40);
  std::vector<MotionEstimate> by_map_id;
  for (int begin : {0, 5}) {
    MotionEstimate e = PerfectWindow(w, {begin, begin + 30}, {{1, 1}, {2, 2}});
    // Every third landmark is not in the window: the compact numbering skips its id.
    for (size_t l = 0; l < e.landmark_cluster.size(); ++l)
      if (l % 3 == 1) {
        e.landmark_cluster[l] = -1;
        e.landmark_in_cluster[l] = Eigen::Vector3d::Constant(NAN);
      }
    by_map_id.push_back(e);
  }
  MapState wide, compact;
  for (const MotionEstimate& e : by_map_id) {
    MotionEstimate c = e;
    std::vector<int> ids;
    c.landmark_cluster.clear();
    c.landmark_in_cluster.clear();
    for (size_t l = 0; l < e.landmark_cluster.size(); ++l) {
      if (e.landmark_cluster[l] < 0) continue;
      ids.push_back(static_cast<int>(l));
      c.landmark_cluster.push_back(e.landmark_cluster[l]);
      c.landmark_in_cluster.push_back(e.landmark_in_cluster[l]);
    }
    wide.Integrate(e);
    compact.Integrate(c, &ids);
  }
  ASSERT_EQ(compact.clusters().size(), wide.clusters().size());
  for (size_t l = 0; l < w.label.size(); ++l) {
    const int id = static_cast<int>(l);
    EXPECT_EQ(compact.ClusterOf(id), wide.ClusterOf(id)) << l;
    if (l % 3 == 1) {
      EXPECT_EQ(compact.ClusterOf(id), -1) << l;
      continue;
    }
    ASSERT_TRUE(compact.WorldPosition(id, 20).has_value()) << l;
    EXPECT_TRUE(testing::MatrixNear(*compact.WorldPosition(id, 20), *wide.WorldPosition(id, 20), 1e-12));
  }
  ExpectFollows(w, compact, 1, 1);
}

TEST(MapState, OptionsRejectAMergeFrameCapBelowTheMotionTestsMinimum) {
  MapStateOptions o;
  o.merge_max_frames = 3;
  EXPECT_THROW(o.Check(), ConfigError);
  o.merge_max_frames = 0;
  EXPECT_NO_THROW(o.Check());
}

TEST(MapState, OptionsRejectACoLocationTestWithoutFrames) {
  MapStateOptions o;
  o.co_location_min_frames = 0;
  EXPECT_THROW(o.Check(), ConfigError);
}

// Object 1 drives for 40 frames and then stands: whether the map folds it into the static
// world depends on how much of its trajectory merging looks at.
bool StoppedObjectFoldsIntoTheStaticWorld(int merge_horizon_frames) {
  World w = MakeWorld(80);
  for (int f = 40; f < 80; ++f) w.world_from_object[0][f] = w.world_from_object[0][40];
  MapStateOptions o;
  o.merge_horizon_frames = merge_horizon_frames;
  MapState map(o);
  bool folded = false;
  for (int begin = 0; begin + 30 <= 80; begin += 5)
    for (const auto& [older, younger] : map.Integrate(PerfectWindow(w, {begin, begin + 30}, {{1, 1}, {2, 2}})).merged)
      folded |= older == 0 && younger == 1;
  return folded;
}

TEST(MapState, MergingLooksAtTheLastHorizonFramesOfATrajectory) {
  EXPECT_FALSE(StoppedObjectFoldsIntoTheStaticWorld(0));   // it moved: never static
  EXPECT_FALSE(StoppedObjectFoldsIntoTheStaticWorld(60));  // 40 still frames, movement in view
  EXPECT_TRUE(StoppedObjectFoldsIntoTheStaticWorld(20));   // only still frames in view
}

TEST(MapState, OptionsRejectANegativeCoLocationRatio) {
  MapStateOptions o;
  o.co_location_ratio = -1;
  EXPECT_THROW(o.Check(), ConfigError);
}

// Windows whose trajectories are exact but whose object landmarks carry independent noise
// (stereo depth noise at range): stitching by the trajectories continues each object without
// a jump; aligning by the noisy shared landmarks makes it jump at every window.
double WorstStitchError(bool stitch_by_motion) {
  const World w = MakeWorld(60);
  MapStateOptions options;
  options.stitch_by_motion = stitch_by_motion;
  options.merge_agreeing_clusters = false;
  MapState map(options);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (int begin = 0; begin + 30 <= 60; begin += 5) {
    MotionEstimate e = PerfectWindow(w, {begin, begin + 30}, {{1, 1}, {2, 2}});
    for (size_t l = 0; l < w.label.size(); ++l)
      if (w.label[l] != 0) e.landmark_in_cluster[l] += testing::Draw3([&] { return noise(rng); });
    map.Integrate(e);
  }
  double worst = 0;
  for (const auto& [id, c] : map.clusters()) {
    const int obj = w.label[id == 1 ? 30 : 45];
    const Pose offset = w.world_from_object[obj - 1][0].inverse() * c.world_from_cluster.at(0);
    for (const auto& [f, pose] : c.world_from_cluster)
      worst = std::max(worst, ((w.world_from_object[obj - 1][f] * offset).inverse() * pose).translation().norm());
  }
  return worst;
}

TEST(MapState, StitchingByTheTrajectoriesIgnoresNoiseInTheSharedLandmarks) {
  EXPECT_LT(WorstStitchError(true), 1e-6);
  EXPECT_GT(WorstStitchError(false), 0.05);
}

TEST(MapState, OptionsRejectAToleranceThatCannotBeMet) {
  MapStateOptions o;
  o.motion_tolerance = 0;
  EXPECT_THROW(o.Check(), ConfigError);
  o = {};
  o.motion_min_frames = 1;
  EXPECT_THROW(o.Check(), ConfigError);
}

TEST(MapState, AWindowWithoutSharedFramesIsMarkedAsAGap) {
  const World w = MakeWorld(80);
  MapState map;
  map.Integrate(PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}}));
  const WindowIntegration info = map.Integrate(PerfectWindow(w, {40, 70}, {{1, 1}, {2, 2}}));
  EXPECT_TRUE(info.gap);
  ASSERT_EQ(map.gaps().size(), 1u);
  EXPECT_EQ(map.gaps()[0], 40);
  EXPECT_FALSE(map.world_from_cam()[35].has_value());
  EXPECT_TRUE(map.world_from_cam()[69].has_value());
}

// Window 0 gets its newest five camera poses 0.3 m and 0.02 rad wrong (the least constrained
// frames of a real window); window 1, which sees them with 25 frames of context, is exact.
std::vector<std::optional<Pose>> CameraAfterABadWindowTip(int refine_camera_from) {
  const World w = MakeWorld(40);
  MapStateOptions options;
  options.refine_camera_from = refine_camera_from;
  MapState map(options);
  MotionEstimate first = PerfectWindow(w, {0, 30}, {{1, 1}, {2, 2}});
  for (int f = 25; f < 30; ++f) first.world_from_cam[f] = first.world_from_cam[f] * MakePose(0.02, 0.3, 0, 0);
  map.Integrate(first);
  const WindowIntegration info = map.Integrate(PerfectWindow(w, {5, 35}, {{1, 1}, {2, 2}}));
  EXPECT_FALSE(info.gap);
  EXPECT_EQ(info.anchor_frame, refine_camera_from > 0 ? 5 + refine_camera_from - 1 : 29);
  return map.world_from_cam();
}

TEST(MapState, RefiningCameraPosesTakesTheLaterWindowsEstimateOfKnownFrames) {
  const World w = MakeWorld(40);
  const std::vector<std::optional<Pose>> refined = CameraAfterABadWindowTip(1);
  ASSERT_EQ(refined.size(), 35u);
  for (int f = 0; f < 35; ++f) {
    ASSERT_TRUE(refined[f].has_value()) << f;
    EXPECT_TRUE(testing::PoseNear(*refined[f], w.world_from_cam[f], 1e-9, 1e-9)) << f;
  }
}

TEST(MapState, WithoutRefinementAFramesFirstEstimateStaysAndLaterFramesChainToIt) {
  const World w = MakeWorld(40);
  const std::vector<std::optional<Pose>> kept = CameraAfterABadWindowTip(0);
  ASSERT_EQ(kept.size(), 35u);
  for (int f = 25; f < 35; ++f) {
    ASSERT_TRUE(kept[f].has_value()) << f;
    EXPECT_FALSE(testing::PoseNear(*kept[f], w.world_from_cam[f], 0.005, 0.1)) << f;
  }
  // Refining from the middle of the window repairs the bad tip too (anchor at frame 19).
  const std::vector<std::optional<Pose>> mid = CameraAfterABadWindowTip(15);
  for (int f = 0; f < 35; ++f)
    EXPECT_TRUE(testing::PoseNear(*mid[f], w.world_from_cam[f], 1e-9, 1e-9)) << f;
}

TEST(MapState, OptionsRejectANegativeRefinementIndex) {
  MapStateOptions o;
  o.refine_camera_from = -1;
  EXPECT_THROW(o.Check(), ConfigError);
}

}  // namespace
}  // namespace cslam

namespace cslam {
namespace {

// A window over `range`: camera driving along z, `statics` static landmarks with ids from
// `first_id`, and (when `mover` ≥ 1) cluster `mover`'s 6 landmarks 100.. sliding along x.
MotionEstimate RetireWindow(FrameRange range, int first_id, int statics, int mover) {
  MotionEstimate e;
  e.range = range;
  Pose window_from_world = Pose::Identity();
  window_from_world.translation() = Eigen::Vector3d(0, 0, -1.0 * range.begin);
  for (int f = range.begin; f < range.end; ++f) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(0, 0, f);
    e.world_from_cam.push_back(window_from_world * p);
  }
  e.landmark_cluster.assign(110, -1);
  e.landmark_in_cluster.assign(110, Eigen::Vector3d::Constant(NAN));
  for (int l = first_id; l < first_id + statics; ++l) {
    e.landmark_cluster[l] = 0;
    e.landmark_in_cluster[l] = window_from_world * Eigen::Vector3d(l % 5, 1, 10 + l);
  }
  if (mover >= 1) {
    ClusterMotion m;
    m.cluster = mover;
    for (int f = range.begin; f < range.end; ++f) {
      Pose body = Pose::Identity();
      body.translation() = Eigen::Vector3d(0.5 * f, 0, 0);
      m.frames.push_back(f);
      m.world_from_cluster.push_back(window_from_world * body);
      m.cam_from_cluster.push_back(e.world_from_cam[f - range.begin].inverse() * m.world_from_cluster.back());
    }
    e.clusters.push_back(m);
    for (int l = 100; l < 106; ++l) {
      e.landmark_cluster[l] = mover;
      e.landmark_in_cluster[l] = Eigen::Vector3d(l - 100, 0, 15);
    }
  }
  return e;
}

TEST(MapState, LandmarksUnseenForAWhileAreRetiredButKeptForTheOutputs) {
  MapStateOptions options;
  options.retire_after_frames = 20;
  MapState map(options);
  map.Integrate(RetireWindow({0, 10}, 0, 30, 1));  // statics 0..29 and the mover
  EXPECT_EQ(map.num_live_landmarks(), 36);
  EXPECT_EQ(map.NumLiveClusters(), 1);
  map.Integrate(RetireWindow({10, 20}, 30, 30, 0));  // statics 30..59 only
  EXPECT_EQ(map.num_live_landmarks(), 66);           // the first window is 10 frames back
  map.Integrate(RetireWindow({35, 45}, 60, 30, 0));  // 25 frames after the first window ended
  EXPECT_EQ(map.num_live_landmarks(), 60);           // 0..29 and the mover's 6 retired
  EXPECT_EQ(map.NumLiveClusters(), 0);
  EXPECT_EQ(map.num_landmarks(), 96);
  // Retired landmarks keep their cluster and place; the cluster keeps its trajectory.
  ASSERT_EQ(map.clusters().size(), 1u);
  const int id = map.clusters().begin()->first;
  EXPECT_EQ(map.clusters().at(id).num_landmarks, 6);
  EXPECT_EQ(map.ClusterOf(100), id);
  EXPECT_EQ(map.ClusterOf(3), 0);
  EXPECT_TRUE(map.WorldPosition(3, 40)->isApprox(Eigen::Vector3d(3, 1, 13), 1e-9));
  EXPECT_EQ(static_cast<int>(map.Landmarks().size()), 96);
  // Released at the end like any unreported cluster: its retired landmarks become outliers.
  map.ReleaseCluster(id);
  EXPECT_EQ(map.ClusterOf(100), -1);
  // A landmark seen again is live again (0..4), while 30..59, last labelled at frame 19,
  // retire now: 60..89 and 0..4 are live.
  map.Integrate(RetireWindow({40, 50}, 0, 5, 0));
  EXPECT_EQ(map.num_live_landmarks(), 35);
  EXPECT_EQ(map.ClusterOf(2), 0);
}

TEST(MapState, NeverRetiringKeepsEveryLandmarkLive) {
  MapStateOptions options;
  options.retire_after_frames = 0;
  MapState map(options);
  map.Integrate(RetireWindow({0, 10}, 0, 30, 1));
  map.Integrate(RetireWindow({100, 110}, 30, 30, 0));
  EXPECT_EQ(map.num_live_landmarks(), 66);
}

}  // namespace
}  // namespace cslam
