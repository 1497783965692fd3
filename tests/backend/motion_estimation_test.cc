#include "backend/motion_estimation.h"

#include <gtest/gtest.h>

#include "backend/full_ba.h"
#include "backend/progressive_dcs.h"
#include "core/errors.h"
#include "tests/backend/synthetic_bodies.h"

namespace cslam {
namespace {

using testing::Ate;
using testing::BodyScene;
using testing::BodySceneSpec;
using testing::MakeBodyScene;

BodySceneSpec NoisyMultiBody() {
  BodySceneSpec spec;
  spec.num_frames = 40;
  spec.num_static = 250;
  spec.num_moving = 3;
  spec.points_per_body = 70;
  spec.pixel_sigma = 1.5;
  return spec;
}

TEST(EstimateMotions, TrueLabelsGiveAnAccurateCameraWhileFullBaIsBiased) {
  const BodyScene scene = MakeBodyScene(NoisyMultiBody());
  const FrameRange range{0, scene.table.num_frames()};
  const MotionEstimate est =
      EstimateMotions(scene.table, scene.camera, range, scene.labels, MotionEstimationOptions{});
  const BackendResult full = RunFullBa(scene.table, scene.camera, range, MotionEstimationOptions{});
  const double ate = Ate(est.world_from_cam, scene.world_from_cam);
  const double ate_full = Ate(full.estimate.world_from_cam, scene.world_from_cam);
  std::printf("camera ATE: true labels %.4f m, full BA %.4f m (travel %.2f m)\n", ate, ate_full,
              scene.world_from_cam.back().translation().norm());
  EXPECT_EQ(full.method, "full-ba");
  // 1.5 px noise at 2.5–10 m with a 0.1 m baseline: a centimetre is the right order.
  EXPECT_LT(ate, 0.02);
  EXPECT_GT(ate_full, 3.0 * ate);
  EXPECT_GT(full.estimate.chi2, est.chi2);
  ASSERT_EQ(est.clusters.size(), 3u);
  for (const ClusterMotion& m : est.clusters) {
    ASSERT_EQ(m.frames.size(), m.cam_from_cluster.size());
    ASSERT_EQ(m.frames.size(), m.world_from_cluster.size());
    const double obj = testing::CentroidTrackRmse(scene, est, m.cluster);
    std::printf("object %d: centroid track RMSE %.4f m over %zu frames\n", m.cluster, obj,
                m.frames.size());
    // 1.5 px noise on a 1 m body 2.8–3.6 m away: one point's depth sigma is 0.2–0.4 m, so
    // a centroid of 70 points is known to ~5 cm per frame from depth alone; bundle
    // adjustment over 40 frames measured 1.2–2.5 cm. The shape initialisation alone is off
    // by 0.1–1 m on the same bodies.
    EXPECT_LT(obj, 0.05);
  }
}

TEST(EstimateMotions, OutputIsIndexedByLandmarkAndFrame) {
  BodySceneSpec spec;
  spec.num_frames = 10;
  spec.num_static = 80;
  spec.num_moving = 1;
  spec.points_per_body = 30;
  const BodyScene scene = MakeBodyScene(spec);
  std::vector<int> labels = scene.labels;
  labels[0] = -1;  // an unused landmark
  const MotionEstimate est =
      EstimateMotions(scene.table, scene.camera, {2, 8}, labels, MotionEstimationOptions{});
  EXPECT_EQ(est.range, (FrameRange{2, 8}));
  EXPECT_EQ(est.world_from_cam.size(), 6u);
  EXPECT_TRUE(est.world_from_cam[0].isApprox(Pose::Identity()));
  EXPECT_EQ(est.landmark_cluster.size(), static_cast<size_t>(scene.table.num_landmarks()));
  EXPECT_EQ(est.landmark_cluster[0], -1);
  EXPECT_FALSE(est.landmark_in_cluster[0].allFinite());
  ASSERT_NE(est.FindCluster(1), nullptr);
  EXPECT_EQ(est.FindCluster(1)->cluster, 1);
  EXPECT_EQ(est.FindCluster(7), nullptr);
  EXPECT_EQ(est.FindCluster(0), nullptr);
  for (int f : est.FindCluster(1)->frames) EXPECT_TRUE(est.range.Contains(f));
  EXPECT_GT(est.num_residuals, 0);
}

// Bit-for-bit equality of two estimates (the cache claims the identical result).
void ExpectIdentical(const MotionEstimate& a, const MotionEstimate& b) {
  EXPECT_EQ(a.landmark_cluster, b.landmark_cluster);
  ASSERT_EQ(a.landmark_in_cluster.size(), b.landmark_in_cluster.size());
  for (size_t i = 0; i < a.landmark_in_cluster.size(); ++i)
    if (a.landmark_in_cluster[i].allFinite() || b.landmark_in_cluster[i].allFinite())
      EXPECT_EQ(a.landmark_in_cluster[i], b.landmark_in_cluster[i]) << "landmark " << i;
  ASSERT_EQ(a.world_from_cam.size(), b.world_from_cam.size());
  for (size_t f = 0; f < a.world_from_cam.size(); ++f)
    EXPECT_EQ(a.world_from_cam[f].matrix(), b.world_from_cam[f].matrix()) << "frame " << f;
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (size_t c = 0; c < a.clusters.size(); ++c) {
    EXPECT_EQ(a.clusters[c].cluster, b.clusters[c].cluster);
    EXPECT_EQ(a.clusters[c].frames, b.clusters[c].frames);
    ASSERT_EQ(a.clusters[c].cam_from_cluster.size(), b.clusters[c].cam_from_cluster.size());
    for (size_t k = 0; k < a.clusters[c].cam_from_cluster.size(); ++k) {
      EXPECT_EQ(a.clusters[c].cam_from_cluster[k].matrix(), b.clusters[c].cam_from_cluster[k].matrix());
      EXPECT_EQ(a.clusters[c].world_from_cluster[k].matrix(),
                b.clusters[c].world_from_cluster[k].matrix());
    }
  }
  EXPECT_EQ(a.chi2, b.chi2);
  EXPECT_EQ(a.num_residuals, b.num_residuals);
}

TEST(EstimateMotions, CachedClustersGiveTheResultOfReEstimatingThem) {
  BodySceneSpec spec = NoisyMultiBody();
  spec.num_moving = 3;
  spec.num_static = 200;
  spec.points_per_body = 30;
  const BodyScene scene = MakeBodyScene(spec);
  const FrameRange range{0, scene.table.num_frames()};
  const MotionEstimationOptions options;
  MovingClusterCache cache;
  const MotionEstimate first =
      EstimateMotions(scene.table, scene.camera, range, scene.labels, options, nullptr, &cache);
  EXPECT_EQ(cache.reused, 0);
  ASSERT_EQ(cache.entries.size(), 3u);

  // The next labelling: body 1 keeps its landmarks under a new label, body 2 loses one
  // landmark to the static world, body 3 is unchanged; warm-started like the outer loop.
  std::vector<int> next = scene.labels;
  int moved = -1;
  for (size_t i = 0; i < next.size(); ++i) {
    if (scene.labels[i] == 1) next[i] = 4;
    if (scene.labels[i] == 2 && moved < 0) moved = static_cast<int>(i);
  }
  ASSERT_GE(moved, 0);
  next[moved] = 0;
  const MotionEstimate cached =
      EstimateMotions(scene.table, scene.camera, range, next, options, &first, &cache);
  EXPECT_EQ(cache.reused, 2);
  const MotionEstimate fresh =
      EstimateMotions(scene.table, scene.camera, range, next, options, &first);
  ExpectIdentical(cached, fresh);

  // Other options invalidate the cache.
  MotionEstimationOptions fewer = options;
  fewer.bundle_adjustment.max_iterations = 5;
  EstimateMotions(scene.table, scene.camera, range, next, fewer, &first, &cache);
  EXPECT_EQ(cache.reused, 0);
}

TEST(EstimateMotions, ProgressiveDcsSplitsOffMovingPoints) {
  BodySceneSpec spec = NoisyMultiBody();
  spec.num_moving = 1;
  spec.num_static = 400;
  spec.points_per_body = 40;
  spec.pixel_sigma = 0.5;
  const BodyScene scene = MakeBodyScene(spec);
  const FrameRange range{0, scene.table.num_frames()};
  const BackendResult r =
      RunProgressiveDcs(scene.table, scene.camera, range, ProgressiveDcsOptions{});
  EXPECT_EQ(r.method, "pdcs");
  ASSERT_FALSE(r.iterations.empty());
  // 400 static points against one 40-point body: the all-static DCS solve follows the static
  // majority, the body's mean errors are 10⁴–10⁵ against < 5 for static points, so the
  // paper's threshold (30 % of the way from the smallest to the largest error) splits off
  // only moving points — but only the worst part of the body, as the rule is relative to
  // the single largest error (the baseline's known weakness).
  int static_kept = 0, static_total = 0, moving_split = 0, moving_total = 0;
  for (int i = 0; i < static_cast<int>(scene.labels.size()); ++i) {
    if (r.estimate.landmark_cluster[i] < 0) continue;
    if (scene.labels[i] == 0) {
      ++static_total;
      static_kept += r.estimate.landmark_cluster[i] == 0;
    } else {
      ++moving_total;
      moving_split += r.estimate.landmark_cluster[i] != 0;
    }
  }
  std::printf("pdcs: %d passes, static kept %d/%d, moving split off %d/%d\n",
              static_cast<int>(r.iterations.size()), static_kept, static_total, moving_split,
              moving_total);
  EXPECT_EQ(static_kept, static_total);
  EXPECT_GE(moving_split, 0.4 * moving_total);
  EXPECT_LE(static_cast<int>(r.iterations.size()), ProgressiveDcsOptions{}.max_passes);
}

// A moving body labelled static: the shape initialisation's fusion gate refuses its points,
// and held out of the adjustment they no longer pull the camera — which then stays closer to
// the truth than when they are adjusted as static points. Static points are rarely refused.
TEST(EstimateMotions, HoldingOutInconsistentLandmarksProtectsTheCamera) {
  BodySceneSpec spec = NoisyMultiBody();
  spec.num_moving = 1;
  spec.num_static = 250;
  spec.points_per_body = 70;
  spec.pixel_sigma = 1.0;
  const BodyScene scene = MakeBodyScene(spec);
  const FrameRange range{0, scene.table.num_frames()};
  const std::vector<int> all_static(scene.labels.size(), 0);
  MotionEstimationOptions o;
  o.shape_init.fusion_gate_chi2 = 16.27;  // the verdict this test holds out by (off by default)
  o.hold_out_inconsistent_landmarks = false;
  const MotionEstimate adjusted =
      EstimateMotions(scene.table, scene.camera, range, all_static, o);
  o.hold_out_inconsistent_landmarks = true;
  const MotionEstimate held = EstimateMotions(scene.table, scene.camera, range, all_static, o);
  const double ate_adjusted = Ate(adjusted.world_from_cam, scene.world_from_cam);
  const double ate_held = Ate(held.world_from_cam, scene.world_from_cam);
  std::printf("camera ATE with a body labelled static: adjusted %.4f m, held out %.4f m\n",
              ate_adjusted, ate_held);
  // Measured 0.29 m adjusted, 0.009 m held out (true labels: 0.002 m); 0.02 m is the bound
  // the true labels meet in TrueLabelsGiveAnAccurateCameraWhileFullBaIsBiased.
  EXPECT_LT(ate_held, 0.1 * ate_adjusted);
  EXPECT_LT(ate_held, 0.02);
  // Every landmark keeps its label and a position.
  for (size_t i = 0; i < all_static.size(); ++i) {
    EXPECT_EQ(held.landmark_cluster[i], adjusted.landmark_cluster[i]) << i;
    if (held.landmark_cluster[i] >= 0) EXPECT_TRUE(held.landmark_in_cluster[i].allFinite()) << i;
  }

  // Without the gate, the run-away guard and the track test nothing is inconsistent: the
  // option changes nothing.
  MotionEstimationOptions no_gate;
  no_gate.shape_init.fusion_gate_chi2 = 0;
  no_gate.shape_init.max_fused_range_ratio = 0;
  no_gate.shape_init.refit_passes = 0;
  no_gate.hold_out_inconsistent_landmarks = false;
  const MotionEstimate a = EstimateMotions(scene.table, scene.camera, range, all_static, no_gate);
  no_gate.hold_out_inconsistent_landmarks = true;
  const MotionEstimate b = EstimateMotions(scene.table, scene.camera, range, all_static, no_gate);
  EXPECT_EQ(a.chi2, b.chi2);
}

TEST(EstimateMotions, PointToPointSwitchReachesTheShapeInitialisation) {
  BodySceneSpec spec;
  spec.outdoor = true;
  spec.num_moving = 0;
  spec.num_static = 300;
  const BodyScene scene = MakeBodyScene(spec);
  MotionEstimationOptions o;
  o.run_bundle_adjustment = false;
  const MotionEstimate aware =
      EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, o);
  o.point_to_point_icp = true;
  const MotionEstimate icp =
      EstimateMotions(scene.table, scene.camera, {0, spec.num_frames}, scene.labels, o);
  EXPECT_LT(Ate(aware.world_from_cam, scene.world_from_cam),
            0.5 * Ate(icp.world_from_cam, scene.world_from_cam));
  // Without bundle adjustment the χ² is still reported, and worse for the ablation.
  EXPECT_GT(aware.num_residuals, 0);
  EXPECT_LT(aware.chi2, icp.chi2);
}

TEST(EstimateMotions, OptionsLoadNestedSections) {
  auto reader = OptionsReader::FromString(
      "point_to_point_icp: true\nshape_init:\n  max_mixture_components: 2\n"
      "bundle_adjustment:\n  robust_kernel: dcs\n",
      "t");
  MotionEstimationOptions o;
  reader.LoadInto(&o);
  EXPECT_TRUE(o.point_to_point_icp);
  EXPECT_EQ(o.shape_init.max_mixture_components, 2);
  EXPECT_EQ(o.bundle_adjustment.robust_kernel, RobustKernel::kDcs);
  o.Check();
  MotionEstimationOptions broken;
  broken.bundle_adjustment.max_iterations = -1;
  try {
    broken.Check();
    ADD_FAILURE() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bundle_adjustment.max_iterations"), std::string::npos)
        << e.what();
  }
  auto bad = OptionsReader::FromString("shape_init:\n  max_mixture: 2\n", "t");
  EXPECT_THROW(bad.LoadInto(&o), ConfigError);
}

}  // namespace
}  // namespace cslam
