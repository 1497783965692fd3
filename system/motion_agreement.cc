#include "system/motion_agreement.h"

#include <cmath>
#include <limits>

namespace cslam {

MotionAgreement CompareMotions(const std::map<int, Pose>& world_from_a,
                               const std::map<int, Pose>& world_from_b,
                               std::vector<Eigen::Vector3d> points_in_b,
                               const std::vector<std::optional<Pose>>& world_from_cam) {
  MotionAgreement result;
  if (points_in_b.size() < 3) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : points_in_b) c += p;
    if (!points_in_b.empty()) c /= static_cast<double>(points_in_b.size());
    if (points_in_b.empty()) points_in_b.push_back(c);
    for (int axis = 0; axis < 3; ++axis) points_in_b.push_back(c + Eigen::Vector3d::Unit(axis));
  }
  // a_from_b is constant for one body: every shared frame says a_from_b = a⁻¹·b. Fit it to
  // all frames at once, on the points, so the error is in metres on the body itself.
  std::vector<Eigen::Vector3d> src, dst;
  double range_sum = 0;
  long long range_n = 0;
  for (const auto& [f, b] : world_from_b) {
    const auto a = world_from_a.find(f);
    if (a == world_from_a.end()) continue;
    ++result.frames;
    const Pose a_from_b_here = a->second.inverse() * b;
    const bool has_cam = f >= 0 && f < static_cast<int>(world_from_cam.size()) && world_from_cam[f];
    for (const auto& p : points_in_b) {
      if (has_cam) {
        range_sum += (b * p - world_from_cam[f]->translation()).norm();
        ++range_n;
      }
      src.push_back(p);
      dst.push_back(a_from_b_here * p);
    }
  }
  if (result.frames == 0) return result;
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
