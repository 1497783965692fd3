#include "system/eval/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_map>

#include "core/errors.h"
#include "core/logging.h"

namespace cslam {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kKittiSegmentLengthsM[] = {100, 200, 300, 400, 500, 600, 700, 800};
constexpr size_t kKittiFirstFrameStep = 10;  // the devkit's "every second" at 10 Hz

void CheckConsistent(const Trajectory& t, const char* which) {
  CSLAM_CHECK(t.timestamps.empty() || t.timestamps.size() == t.size(),
              std::string(which) + " trajectory: timestamps must be empty or one per pose");
  CSLAM_CHECK(t.frames.empty() || t.frames.size() == t.size(),
              std::string(which) + " trajectory: frames must be empty or one per pose");
}

// Index in sorted `stamps` of the nearest value to `t`; ties go to the earlier one (numpy's
// argmin, which evo uses).
size_t NearestIndex(const std::vector<double>& stamps, double t) {
  const size_t p = size_t(std::lower_bound(stamps.begin(), stamps.end(), t) - stamps.begin());
  if (p == 0) {
    return 0;
  }
  if (p == stamps.size()) {
    return p - 1;
  }
  return (t - stamps[p - 1]) <= (stamps[p] - t) ? p - 1 : p;
}

// The pose pairs of an association, ground truth first.
struct PosePairs {
  std::vector<Pose> gt, est;
};

PosePairs Paired(const Trajectory& gt, const Trajectory& est, const AssociationOptions& options) {
  const TrajectoryAssociation a = Associate(gt, est, options);
  PosePairs out;
  out.gt.reserve(a.size());
  out.est.reserve(a.size());
  for (size_t k = 0; k < a.size(); ++k) {
    out.gt.push_back(gt.poses[a.gt[k]]);
    out.est.push_back(est.poses[a.est[k]]);
  }
  return out;
}

// evo's relative pose error of a pair (i, j): (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j).
Pose RelativeError(const PosePairs& p, size_t i, size_t j) {
  return (p.gt[i].inverse() * p.gt[j]).inverse() * (p.est[i].inverse() * p.est[j]);
}

// Accumulates translational and rotational errors into RMSE and mean.
struct RpeAccumulator {
  double t_sq = 0, r_sq = 0, t_sum = 0, r_sum = 0;
  size_t n = 0;
  void Add(const Pose& e) {
    const double t = e.translation().norm(), r = RotationAngle(e.linear());
    t_sq += t * t;
    r_sq += r * r;
    t_sum += t;
    r_sum += r;
    ++n;
  }
  RpeResult Result(int delta) const {
    if (n == 0) {
      return {kNaN, kNaN, kNaN, kNaN, 0, delta};
    }
    const double dn = double(n);
    return {std::sqrt(t_sq / dn), std::sqrt(r_sq / dn), t_sum / dn, r_sum / dn, n, delta};
  }
};

// Uniform integer in [0, n) from one 32-bit draw (Lemire's multiply-shift); unlike
// std::uniform_int_distribution it gives the same sequence with every standard library.
size_t UniformIndex(std::mt19937& rng, size_t n) {
  return size_t((uint64_t(rng()) * uint64_t(n)) >> 32);
}

}  // namespace

TrajectoryAssociation Associate(const Trajectory& gt, const Trajectory& est,
                                const AssociationOptions& options) {
  CheckConsistent(gt, "ground-truth");
  CheckConsistent(est, "estimated");
  using Mode = AssociationOptions::Mode;
  Mode mode = options.mode;
  if (mode == Mode::kAuto) {
    if (gt.HasFrames() && est.HasFrames()) {
      mode = Mode::kFrame;
    } else if (gt.HasTimestamps() && est.HasTimestamps()) {
      mode = Mode::kTimestamp;
    } else {
      mode = Mode::kIndex;
    }
  }
  TrajectoryAssociation out;
  switch (mode) {
    case Mode::kFrame: {
      CSLAM_CHECK(gt.HasFrames() && est.HasFrames(), "frame association needs frames on both");
      std::unordered_map<int, size_t> est_of_frame;
      for (size_t k = 0; k < est.size(); ++k) {
        est_of_frame.emplace(est.frames[k], k);
      }
      for (size_t k = 0; k < gt.size(); ++k) {
        const auto it = est_of_frame.find(gt.frames[k]);
        if (it == est_of_frame.end()) {
          continue;
        }
        out.gt.push_back(k);
        out.est.push_back(it->second);
      }
      break;
    }
    case Mode::kTimestamp: {
      CSLAM_CHECK(gt.HasTimestamps() && est.HasTimestamps(),
                  "timestamp association needs timestamps on both");
      CSLAM_CHECK(std::is_sorted(gt.timestamps.begin(), gt.timestamps.end()) &&
                      std::is_sorted(est.timestamps.begin(), est.timestamps.end()),
                  "timestamp association needs non-decreasing timestamps");
      // evo snaps the shorter trajectory onto the longer one.
      const bool est_is_short = est.size() <= gt.size();
      const std::vector<double>& short_stamps = est_is_short ? est.timestamps : gt.timestamps;
      const std::vector<double>& long_stamps = est_is_short ? gt.timestamps : est.timestamps;
      if (long_stamps.empty()) {
        break;
      }
      for (size_t k = 0; k < short_stamps.size(); ++k) {
        const size_t m = NearestIndex(long_stamps, short_stamps[k]);
        if (std::abs(long_stamps[m] - short_stamps[k]) > options.max_time_difference_s) {
          continue;
        }
        out.gt.push_back(est_is_short ? m : k);
        out.est.push_back(est_is_short ? k : m);
      }
      break;
    }
    case Mode::kIndex:
    case Mode::kAuto:
      for (size_t k = 0; k < std::min(gt.size(), est.size()); ++k) {
        out.gt.push_back(k);
        out.est.push_back(k);
      }
      break;
  }
  return out;
}

AteResult ComputeAte(const Trajectory& gt, const Trajectory& est, bool with_scale,
                     const AssociationOptions& association) {
  const PosePairs p = Paired(gt, est, association);
  AteResult out{kNaN, kNaN, kNaN, kNaN, Sim3{}, p.gt.size()};
  if (p.gt.size() < 3) {
    GetLogger("system")->warn("ATE needs at least 3 associated poses, got {}", p.gt.size());
    return out;
  }
  std::vector<Eigen::Vector3d> src, dst;
  for (size_t k = 0; k < p.gt.size(); ++k) {
    src.push_back(p.est[k].translation());
    dst.push_back(p.gt[k].translation());
  }
  out.alignment = AlignUmeyama(src, dst, with_scale);
  std::vector<double> errors(src.size());
  double sq = 0, sum = 0;
  for (size_t k = 0; k < src.size(); ++k) {
    errors[k] = (dst[k] - out.alignment.Apply(src[k])).norm();
    sq += errors[k] * errors[k];
    sum += errors[k];
  }
  const double n = double(errors.size());
  out.rmse_m = std::sqrt(sq / n);
  out.mean_m = sum / n;
  std::sort(errors.begin(), errors.end());
  const size_t mid = errors.size() / 2;
  out.median_m = errors.size() % 2 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  out.max_m = errors.back();
  return out;
}

RpeResult ComputeRpePerFrame(const Trajectory& gt, const Trajectory& est, int delta,
                             const AssociationOptions& association) {
  CSLAM_CHECK(delta >= 1, "RPE delta must be >= 1");
  const PosePairs p = Paired(gt, est, association);
  RpeAccumulator acc;
  const size_t step = size_t(delta);
  for (size_t i = 0; i + step < p.gt.size(); i += step) {
    acc.Add(RelativeError(p, i, i + step));
  }
  return acc.Result(delta);
}

RpeResult ComputeRpeAllPairs(const Trajectory& gt, const Trajectory& est, size_t max_pairs,
                             uint32_t seed, const AssociationOptions& association) {
  const PosePairs p = Paired(gt, est, association);
  const size_t n = p.gt.size();
  RpeAccumulator acc;
  if (n < 2 || max_pairs == 0) {
    return acc.Result(0);
  }
  if (n * (n - 1) <= max_pairs) {
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < n; ++j) {
        if (i != j) {
          acc.Add(RelativeError(p, i, j));
        }
      }
    }
  } else {
    std::mt19937 rng(seed);
    while (acc.n < max_pairs) {
      const size_t i = UniformIndex(rng, n), j = UniformIndex(rng, n);
      if (i != j) {
        acc.Add(RelativeError(p, i, j));
      }
    }
  }
  return acc.Result(0);
}

KittiSegmentError ComputeKittiSegmentErrors(const Trajectory& gt, const Trajectory& est,
                                            const AssociationOptions& association) {
  const PosePairs p = Paired(gt, est, association);
  KittiSegmentError out{kNaN, kNaN, 0, false};
  const size_t n = p.gt.size();
  if (n < 2) {
    return out;
  }
  std::vector<double> dist(n, 0.0);
  for (size_t k = 1; k < n; ++k) {
    dist[k] = dist[k - 1] + (p.gt[k].translation() - p.gt[k - 1].translation()).norm();
  }
  double t_sum = 0, r_sum = 0;
  for (size_t first = 0; first < n; first += kKittiFirstFrameStep) {
    for (double length : kKittiSegmentLengthsM) {
      size_t last = first;
      while (last < n && !(dist[last] > dist[first] + length)) {
        ++last;
      }
      if (last == n) {
        continue;
      }
      const Pose delta_gt = p.gt[first].inverse() * p.gt[last];
      const Pose delta_est = p.est[first].inverse() * p.est[last];
      const Pose error = delta_est.inverse() * delta_gt;
      t_sum += error.translation().norm() / length;
      r_sum += RotationAngle(error.linear()) / length;
      ++out.segments;
    }
  }
  if (out.segments == 0) {
    return out;
  }
  out.defined = true;
  out.t_rel_percent = 100.0 * t_sum / double(out.segments);
  out.r_rel_deg_per_m = (180.0 / M_PI) * r_sum / double(out.segments);
  return out;
}

double PathLength(const Trajectory& trajectory) {
  double length = 0;
  for (size_t k = 1; k < trajectory.size(); ++k) {
    length += (trajectory.poses[k].translation() - trajectory.poses[k - 1].translation()).norm();
  }
  return length;
}

Trajectory ApplySim3(const Sim3& s, const Trajectory& est) {
  Trajectory out = est;
  for (Pose& pose : out.poses) {
    pose.translation() = s.Apply(pose.translation());
    pose.linear() = s.rigid.linear() * pose.linear();
  }
  return out;
}

}  // namespace cslam
