#include "backend/point_tracks.h"

#include <gtest/gtest.h>

#include "tests/backend/fake_motion_estimator.h"
#include "tests/backend/test_scene.h"
#include "tests/support/matchers.h"

namespace cslam {
namespace {

using testing::MatrixNear;

testing::TestScene Scene(double noise_px) {
  std::vector<testing::TestBody> bodies(2);
  bodies[0].points_in_body = testing::RandomPoints(20, {-3, -1, 4}, {3, 1, 8}, 1);
  bodies[0].world_from_body = [](int) { return Pose::Identity(); };
  bodies[1].points_in_body = testing::RandomPoints(15, {-0.4, -0.4, -0.4}, {0.4, 0.4, 0.4}, 2);
  bodies[1].world_from_body = [](int t) {
    return testing::YawPose(0.02 * t, Eigen::Vector3d(-1 + 0.02 * t, 0, 4));
  };
  return testing::MakeScene(testing::SyntheticCamera(false), bodies, 40,
                            [](int t) { return testing::YawPose(0.003 * t, {0, 0, 0.02 * t}); },
                            noise_px, 1.0, 3);
}

TEST(PointTracks, BackProjectionIsTheCameraFramePointAndItsCovariance) {
  const auto s = Scene(0.0);
  const PointTracks tracks = BackProjectTracks(s.table, s.camera, {5, 30});
  ASSERT_EQ(tracks.size(), static_cast<size_t>(s.table.num_landmarks()));
  const auto obs = s.table.ObservationsOf(0, {5, 30});
  ASSERT_EQ(tracks[0].samples.size(), obs.size());
  EXPECT_EQ(tracks[0].samples.front().frame, 5);
  Eigen::Vector3d p;
  s.camera.BackProject<double>(obs[0].x, &p);
  EXPECT_TRUE(MatrixNear(tracks[0].samples[0].point, p, 1e-12));
  EXPECT_TRUE(MatrixNear(tracks[0].samples[0].cov, s.camera.PointCovariance(obs[0].x, obs[0].cov), 1e-15));
}

TEST(PointTracks, RefinedPointsStayInTheCameraFrame) {
  // With zero noise the model explains every observation, so the refined point equals the
  // back-projection (camera frame) for static and moving landmarks alike, and the covariance
  // shrinks by the number of averaged frames.
  const auto s = Scene(0.0);
  const FrameRange range{0, 40};
  const auto est = testing::FakeEstimateMotions(s.table, s.camera, range, s.truth, {});
  const PointTracks raw = BackProjectTracks(s.table, s.camera, range);
  const PointTracks refined = RefineTracks(s.table, s.camera, range, est, 2);
  for (int l : {0, 25}) {
    ASSERT_EQ(refined[l].samples.size(), raw[l].samples.size());
    const size_t mid = raw[l].samples.size() / 2;
    EXPECT_TRUE(MatrixNear(refined[l].samples[mid].point, raw[l].samples[mid].point, 1e-6));
    EXPECT_LT(refined[l].samples[mid].cov.trace(), raw[l].samples[mid].cov.trace() / 3);
  }
  const PointTracks same = RefineTracks(s.table, s.camera, range, est, 0);
  EXPECT_TRUE(MatrixNear(same[3].samples[7].point, raw[3].samples[7].point, 0));
}

TEST(PointTracks, RefinementReducesNoise) {
  const auto s = Scene(1.0);
  const auto truth = Scene(0.0);
  const FrameRange range{0, 40};
  const auto est = testing::FakeEstimateMotions(s.table, s.camera, range, s.truth, {});
  const PointTracks raw = BackProjectTracks(s.table, s.camera, range);
  const PointTracks exact = BackProjectTracks(truth.table, truth.camera, range);
  const PointTracks refined = RefineTracks(s.table, s.camera, range, est, 2);
  double err_raw = 0, err_refined = 0;
  for (int l = 0; l < s.table.num_landmarks(); ++l)
    for (size_t k = 0; k < raw[l].samples.size() && k < exact[l].samples.size(); ++k) {
      if (raw[l].samples[k].frame != exact[l].samples[k].frame) continue;
      err_raw += (raw[l].samples[k].point - exact[l].samples[k].point).squaredNorm();
      err_refined += (refined[l].samples[k].point - exact[l].samples[k].point).squaredNorm();
    }
  EXPECT_LT(err_refined, 0.5 * err_raw);
}

}  // namespace
}  // namespace cslam
