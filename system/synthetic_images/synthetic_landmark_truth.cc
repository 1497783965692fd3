#include "system/synthetic_images/synthetic_landmark_truth.h"

#include <cmath>
#include <map>

#include "system/synthetic_images/synthetic_renderer.h"

namespace cslam {

namespace {

/// Far end of a cast ray, metres: beyond every synthetic scene.
constexpr double kRayLength = 5000.0;

}  // namespace

LandmarkTruth LabelLandmarksByIdImages(const TrackletTable& table, const SyntheticSequence& seq,
                                       const std::function<cv::Mat(int)>& object_ids) {
  const int n = table.num_landmarks();
  LandmarkTruth truth;
  truth.object.assign(n, -1);
  truth.in_object.assign(n, Eigen::Vector3d::Zero());
  // Landmarks by the frame they start in, so each id image is read once.
  std::map<int, std::vector<int>> by_first_frame;
  for (int l = 0; l < n; ++l) {
    const auto obs = table.ObservationsOf(l);
    if (!obs.empty() && obs.front().frame < seq.num_frames()) by_first_frame[obs.front().frame].push_back(l);
  }
  const StereoCamera& cam = seq.camera;
  for (const auto& [frame, landmarks] : by_first_frame) {
    const cv::Mat ids = object_ids(frame);
    for (int l : landmarks) {
      const StereoObservation& o = table.ObservationsOf(l).front();
      const int u = static_cast<int>(std::lround(o.x(0))), v = static_cast<int>(std::lround(o.x(1)));
      if (u < 0 || v < 0 || u >= ids.cols || v >= ids.rows) continue;
      const int body = ids.at<uint16_t>(v, u);
      if (body == kNoObjectId || body >= seq.num_objects()) continue;
      const Pose body_from_cam = seq.world_from_object[body][frame].inverse() * seq.world_from_cam[frame];
      const Eigen::Vector3d ray((o.x(0) - cam.cx) / cam.fx, (o.x(1) - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d a = body_from_cam.translation();
      const Eigen::Vector3d b = body_from_cam * (kRayLength * ray.normalized());
      double best = 2.0;
      for (const SceneQuad& q : seq.geometry.bodies[body].quads) {
        const double t = IntersectSegment(q, a, b);
        if (t > 0.0 && t < best) best = t;
      }
      Eigen::Vector3d p;
      if (best <= 1.0) {
        p = a + best * (b - a);
      } else {
        Eigen::Vector3d in_cam;
        if (!cam.BackProject<double>(o.x, &in_cam)) continue;
        p = body_from_cam * in_cam;
      }
      truth.object[l] = body;
      truth.in_object[l] = p;
    }
  }
  return truth;
}

}  // namespace cslam
