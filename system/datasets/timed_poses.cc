#include "system/datasets/timed_poses.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

namespace {

// Reads lines of numbers; `layout` turns one line's numbers into (time, pose).
template <typename Layout>
TimedPoses ReadPoses(const std::string& path, const std::string& what, char separator, size_t min_fields,
                     Layout layout) {
  std::ifstream in = OpenTextFile(path, what);
  TimedPoses out;
  out.path = path;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (separator != ' ') std::replace(line.begin(), line.end(), separator, ' ');
    const std::vector<double> v = ParseNumbers(line, path, line_no);
    if (v.size() < min_fields)
      throw InputError(path, line_no, "expected " + std::to_string(min_fields) + " numbers (" + what +
                                          "), got " + std::to_string(v.size()));
    double t = 0;
    Eigen::Quaterniond q;
    Eigen::Vector3d p;
    layout(v, &t, &p, &q);
    if (std::abs(q.norm() - 1.0) > 1e-2)
      throw InputError(path, line_no, "expected a unit quaternion, its norm is " + std::to_string(q.norm()));
    if (!out.times.empty() && t <= out.times.back())
      throw InputError(path, line_no, "expected increasing timestamps");
    Pose pose = Pose::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = p;
    out.times.push_back(t);
    out.world_from_body.push_back(pose);
  }
  if (out.times.empty()) throw InputError(path, "expected ground-truth poses; the file has none");
  return out;
}

}  // namespace

TimedPoses ReadTumPoses(const std::string& path) {
  return ReadPoses(path, "TUM ground truth: t tx ty tz qx qy qz qw", ' ', 8,
                   [](const std::vector<double>& v, double* t, Eigen::Vector3d* p, Eigen::Quaterniond* q) {
                     *t = v[0];
                     *p = Eigen::Vector3d(v[1], v[2], v[3]);
                     *q = Eigen::Quaterniond(v[7], v[4], v[5], v[6]);
                   });
}

TimedPoses ReadAslPoses(const std::string& path) {
  return ReadPoses(path, "ASL ground truth: timestamp_ns, px, py, pz, qw, qx, qy, qz", ',', 8,
                   [](const std::vector<double>& v, double* t, Eigen::Vector3d* p, Eigen::Quaterniond* q) {
                     *t = v[0] * 1e-9;
                     *p = Eigen::Vector3d(v[1], v[2], v[3]);
                     *q = Eigen::Quaterniond(v[4], v[5], v[6], v[7]);
                   });
}

std::vector<Pose> InterpolatePoses(const TimedPoses& poses, const std::vector<double>& times,
                                   double tolerance_s, double max_gap_s) {
  std::vector<Pose> out;
  out.reserve(times.size());
  const std::vector<double>& gt = poses.times;
  for (size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    if (t < gt.front() - tolerance_s || t > gt.back() + tolerance_s) {
      std::ostringstream s;
      s.precision(15);
      s << "does not cover image " << i << " at t = " << t << " s: expected poses from before the first "
        << "to after the last image, the file spans " << gt.front() << " - " << gt.back() << " s";
      throw InputError(poses.path, s.str());
    }
    const size_t hi = static_cast<size_t>(std::lower_bound(gt.begin(), gt.end(), t) - gt.begin());
    if (hi == 0) {
      out.push_back(poses.world_from_body.front());
      continue;
    }
    if (hi == gt.size()) {
      out.push_back(poses.world_from_body.back());
      continue;
    }
    const size_t lo = hi - 1;
    if (gt[hi] - gt[lo] > max_gap_s) {
      std::ostringstream s;
      s.precision(15);
      s << "has a gap of " << gt[hi] - gt[lo] << " s around image " << i << " (t = " << t
        << " s); expected poses at most " << max_gap_s << " s apart";
      throw InputError(poses.path, s.str());
    }
    out.push_back(Interpolate(poses.world_from_body[lo], poses.world_from_body[hi],
                              (t - gt[lo]) / (gt[hi] - gt[lo])));
  }
  return out;
}

}  // namespace cslam
