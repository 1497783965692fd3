#include "system/eval/object_camera_frame_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/rigid.h"

namespace cslam {
namespace {

// A car 15-40 m ahead of a camera that drives behind it, turning through 90° over `n` frames.
struct Scene {
  std::vector<Pose> world_from_cam, world_from_object;
};

Scene TurningCarAhead(int n) {
  Scene s;
  for (int k = 0; k < n; ++k) {
    const double a = 0.5 * M_PI * k / (n - 1);
    Pose cam = Pose::Identity(), car = Pose::Identity();
    cam.linear() = ExpSO3(Eigen::Vector3d(0, 0.3 * a, 0));
    cam.translation() = Eigen::Vector3d(-10 * (1 - std::cos(0.3 * a)), 0, 10 * std::sin(0.3 * a));
    car.linear() = ExpSO3(Eigen::Vector3d(0, a, 0));
    car.translation() = Eigen::Vector3d(-20 * (1 - std::cos(a)), 0.5, 15 + 20 * std::sin(a));
    s.world_from_cam.push_back(cam);
    s.world_from_object.push_back(car);
  }
  return s;
}

Pose CamFromObject(const Scene& s, int k) {
  return s.world_from_cam[k].inverse() * s.world_from_object[k];
}

TEST(ObjectCameraFrameError, ADriftThatCarriesCameraAndObjectTogetherIsNoError) {
  // The estimate's world drifts (a growing rotation and offset, as a camera's drift does); the
  // object is placed exactly relative to the camera, so only the world-frame figures see it.
  const Scene truth = TurningCarAhead(50);
  std::vector<ObjectInCamera> frames;
  for (int k = 0; k < 50; ++k) {
    Vector6d xi;
    xi << 0.002 * k, 0.004 * k, 0, 0.05 * k, 0, -0.03 * k;
    const Pose drift = PoseFromVector(xi);
    const Pose est_cam = drift * truth.world_from_cam[k];
    const Pose est_object = drift * truth.world_from_object[k];
    frames.push_back({est_cam.inverse() * est_object.translation(), CamFromObject(truth, k)});
  }
  const ObjectCameraFrameError e = ObjectErrorInCameraFrame(frames, false);
  EXPECT_EQ(e.frames, 50);
  EXPECT_LT(e.rmse_m, 1e-9);
}

TEST(ObjectCameraFrameError, FindsTheTrackedPointOnATurningObjectAndMeasuresOnlyTheNoise) {
  // The estimate tracks the centroid of the landmarks seen on the car's rear and left side, not
  // the box centre; with 0.1 m of noise per axis the error is the noise, √3·0.1 m.
  const Scene truth = TurningCarAhead(200);
  const Eigen::Vector3d on_car(-1.6, -0.2, 0.7);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<ObjectInCamera> frames;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d n(noise(rng), noise(rng), noise(rng));
    frames.push_back({CamFromObject(truth, k) * on_car + n, CamFromObject(truth, k)});
  }
  const ObjectCameraFrameError fitted = ObjectErrorInCameraFrame(frames, true);
  EXPECT_LT((fitted.point_in_object - on_car).norm(), 0.05);
  EXPECT_NEAR(fitted.rmse_m, std::sqrt(3.0) * 0.1, 0.02);
  // Taken for the box centre, the same track is off by the point's distance from it.
  const ObjectCameraFrameError centre = ObjectErrorInCameraFrame(frames, false);
  EXPECT_NEAR(centre.rmse_m, on_car.norm(), 0.05);
}

TEST(ObjectCameraFrameError, AnErrorInDepthThatChangesIsNotTakenOutByTheFit) {
  // Half the frames 0.5 m too far, half 0.5 m too near along the camera's axis: no fixed point
  // on the object explains that, so the whole 0.5 m remains.
  const Scene truth = TurningCarAhead(100);
  std::vector<ObjectInCamera> frames;
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d depth_error(0, 0, k % 2 == 0 ? 0.5 : -0.5);
    frames.push_back({CamFromObject(truth, k).translation() + depth_error, CamFromObject(truth, k)});
  }
  EXPECT_NEAR(ObjectErrorInCameraFrame(frames, true).rmse_m, 0.5, 0.02);
}

TEST(ObjectCameraFrameError, FewerThanThreeFramesHaveNoFigure) {
  const Scene truth = TurningCarAhead(2);
  std::vector<ObjectInCamera> frames;
  for (int k = 0; k < 2; ++k)
    frames.push_back({CamFromObject(truth, k).translation(), CamFromObject(truth, k)});
  EXPECT_TRUE(std::isnan(ObjectErrorInCameraFrame(frames, true).rmse_m));
}

}  // namespace
}  // namespace cslam
