#include "system/map/motion_agreement.h"

#include <cmath>
#include <limits>

#include "system/map/shared_frames.h"

namespace cslam {

MotionAgreement CompareMotions(const std::map<int, Pose>& world_from_a,
                               const std::map<int, Pose>& world_from_b,
                               const std::vector<Eigen::Vector3d>& given_points,
                               const std::vector<std::optional<Pose>>& world_from_cam,
                               int min_frames, int max_frames) {
  MotionAgreement result;
  // The shared frames, by walking both (frame-ordered) maps once.
  std::vector<std::pair<const Pose*, const Pose*>> shared;  // (a, b) per shared frame
  std::vector<int> shared_frames;
  ForEachSharedFrame(world_from_a, world_from_b, [&](int f, const Pose& a, const Pose& b) {
    shared.emplace_back(&a, &b);
    shared_frames.push_back(f);
  });
  result.frames = static_cast<int>(shared.size());
  if (result.frames == 0 || result.frames < min_frames) return result;
  if (max_frames > 0 && result.frames > max_frames) {
    const size_t n = shared.size();
    for (size_t k = 0; k < static_cast<size_t>(max_frames); ++k) {
      const size_t from = max_frames == 1 ? n - 1 : k * (n - 1) / static_cast<size_t>(max_frames - 1);
      shared[k] = shared[from];
      shared_frames[k] = shared_frames[from];
    }
    shared.resize(max_frames);
    shared_frames.resize(max_frames);
  }
  std::vector<Eigen::Vector3d> padded;
  const std::vector<Eigen::Vector3d>* points = &given_points;
  if (given_points.size() < 3) {
    padded = given_points;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : padded) c += p;
    if (!padded.empty()) c /= static_cast<double>(padded.size());
    if (padded.empty()) padded.push_back(c);
    for (int axis = 0; axis < 3; ++axis) padded.push_back(c + Eigen::Vector3d::Unit(axis));
    points = &padded;
  }
  // a_from_b is constant for one body: every shared frame says a_from_b = a⁻¹·b. Fit it to
  // all frames at once, on the points, so the error is in metres on the body itself.
  std::vector<Eigen::Vector3d> src, dst;
  src.reserve(shared.size() * points->size());
  dst.reserve(shared.size() * points->size());
  double range_sum = 0;
  long long range_n = 0;
  for (size_t k = 0; k < shared.size(); ++k) {
    const int f = shared_frames[k];
    const Pose& b = *shared[k].second;
    const Pose a_from_b_here = shared[k].first->inverse() * b;
    const bool has_cam = f >= 0 && f < static_cast<int>(world_from_cam.size()) && world_from_cam[f];
    for (const auto& p : *points) {
      if (has_cam) {
        range_sum += (b * p - world_from_cam[f]->translation()).norm();
        ++range_n;
      }
      src.push_back(p);
      dst.push_back(a_from_b_here * p);
    }
  }
  result.a_from_b = AlignUmeyama(src, dst, false).rigid;
  double se = 0;
  for (size_t i = 0; i < src.size(); ++i) se += (result.a_from_b * src[i] - dst[i]).squaredNorm();
  result.rms_m = std::sqrt(se / static_cast<double>(src.size()));
  if (range_n > 0) result.mean_range_m = range_sum / static_cast<double>(range_n);
  return result;
}

double MotionAgreement::relative_rms() const {
  return mean_range_m > 0 ? rms_m / mean_range_m : std::numeric_limits<double>::infinity();
}

std::map<int, Pose> StaticTrajectory(const std::map<int, Pose>& frames) {
  std::map<int, Pose> out;
  for (const auto& [f, pose] : frames) out.emplace_hint(out.end(), f, Pose::Identity());
  return out;
}

}  // namespace cslam
