#include "backend/window_prior.h"

#include <algorithm>

#include "core/errors.h"

namespace cslam {

int WindowPrior::KnownFrames() const {
  return static_cast<int>(std::count_if(world_from_cam.begin(), world_from_cam.end(),
                                        [](const std::optional<Pose>& p) { return p.has_value(); }));
}

int WindowPrior::ClusterOf(int landmark) const {
  return landmark >= 0 && landmark < static_cast<int>(landmark_cluster.size())
             ? landmark_cluster[landmark]
             : -1;
}

namespace {

// The pose of `frame` registered on the prior's static landmarks it observes, from `start`;
// nullopt when fewer than options.min_points of them back-project there.
std::optional<Pose> RegisterOnStatic(const WindowPrior& prior, const TrackletTable& table,
                                     const StereoCamera& camera, int frame, const Pose& start,
                                     const ShapeInitOptions& options) {
  if (frame >= table.num_frames()) return std::nullopt;
  const Eigen::Matrix3d R = start.linear();
  std::vector<RegistrationPoint> points;
  for (const ObservationRef& ref : table.ObservationsAt(frame)) {
    if (prior.ClusterOf(ref.landmark) != 0) continue;
    const Eigen::Vector3d& model = prior.static_point[ref.landmark];
    if (!model.allFinite()) continue;
    const StereoObservation& o = table.Get(ref);
    Eigen::Vector3d p;
    if (!camera.BackProject<double>(o.x, &p)) continue;
    const Eigen::Matrix3d cov = camera.PointCovariance(o.x, o.cov);
    // The map position is the mean of many observations; one observation's spread, rotated
    // into the world at the predicted pose, is a conservative stand-in for its uncertainty.
    points.push_back({p, cov, model, {R * cov * R.transpose()}});
  }
  if (static_cast<int>(points.size()) < options.min_points) return std::nullopt;
  const Pose pose = RegisterNoiseAware(points, start, options);
  if (!pose.matrix().allFinite()) return std::nullopt;
  return pose;
}

}  // namespace

std::vector<Pose> CompleteCameraPoses(const WindowPrior& prior, const TrackletTable& table,
                                      const StereoCamera& camera, const ShapeInitOptions& options) {
  const int n = prior.range.size();
  CSLAM_CHECK(static_cast<int>(prior.world_from_cam.size()) == n,
              "a window prior needs one (possibly unknown) camera pose per frame");
  CSLAM_CHECK(prior.KnownFrames() > 0, "a window prior needs at least one known camera pose");
  std::vector<std::optional<Pose>> poses = prior.world_from_cam;
  // Constant velocity from the two neighbours on the known side (`step` = +1 forwards).
  auto predict = [&](int k, int step) {
    const Pose& last = *poses[k - step];
    const int before = k - 2 * step;
    if (before < 0 || before >= n || !poses[before]) return last;
    return Pose(last * (poses[before]->inverse() * last));
  };
  auto fill = [&](int k, int step) {
    const Pose start = predict(k, step);
    poses[k] = RegisterOnStatic(prior, table, camera, prior.range.begin + k, start, options)
                   .value_or(start);
  };
  for (int k = 1; k < n; ++k)
    if (!poses[k] && poses[k - 1]) fill(k, +1);
  for (int k = n - 2; k >= 0; --k)
    if (!poses[k] && poses[k + 1]) fill(k, -1);
  std::vector<Pose> out(n);
  for (int k = 0; k < n; ++k) out[k] = *poses[k];
  return out;
}

}  // namespace cslam
