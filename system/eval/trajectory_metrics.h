#pragma once
// Trajectory error metrics with evo's and the KITTI devkit's definitions (docs/formats.md,
// clusterslam_spec.md §9). Every function first associates the estimate with the ground truth
// (see Associate) and then works on the associated pairs in ground-truth order.
//
// Object trajectories: their world origin is arbitrary, so each object is evaluated on its own
// with ComputeAte (SE(3) Umeyama alignment per object) and the RPE functions (alignment-free);
// no separate object variant is needed.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/rigid.h"
#include "system/eval/trajectory.h"

namespace cslam {

/// How ground-truth and estimated poses are paired.
struct AssociationOptions {
  enum class Mode {
    kAuto,   ///< frames when both have frames, else timestamps when both have them, else by index
    kFrame,  ///< equal frame index
    kTimestamp,  ///< nearest timestamp within max_time_difference_s (evo's rule)
    kIndex,      ///< k-th pose with k-th pose (evo's rule for KITTI files; sizes may differ)
  };
  Mode mode = Mode::kAuto;
  double max_time_difference_s = 0.01;  ///< seconds; evo's default
};

/// Indices of associated poses: gt.poses[gt[k]] pairs with est.poses[est[k]].
struct TrajectoryAssociation {
  std::vector<size_t> gt;
  std::vector<size_t> est;
  size_t size() const { return gt.size(); }
};

/// Pairs the poses of `gt` and `est`. By timestamp it follows evo's
/// `associate_trajectories`: each pose of the shorter trajectory takes the nearest timestamp of
/// the longer one when it is within max_time_difference_s.
TrajectoryAssociation Associate(const Trajectory& gt, const Trajectory& est,
                                const AssociationOptions& options = {});

/// Absolute trajectory error (evo_ape -a, or -as with scale): positions of `est` aligned to
/// `gt` by Umeyama, statistics of ‖gt_k − (s R p̂_k + t)‖. `alignment` maps est into gt's frame.
/// Fewer than 3 associated poses: NaN statistics and an identity alignment (count says how many).
struct AteResult {
  double rmse_m;
  double mean_m;
  double median_m;
  double max_m;
  Sim3 alignment;
  size_t count;
};

AteResult ComputeAte(const Trajectory& gt, const Trajectory& est, bool with_scale = false,
                     const AssociationOptions& association = {});

/// Relative pose error statistics: translational part in metres, rotation angle in radians.
/// RMSE and mean over `count` pose pairs. NaN when count == 0.
struct RpeResult {
  double trans_rmse_m, rot_rmse_rad, trans_mean_m, rot_mean_rad;
  size_t count;
  int delta;  ///< frames between the two poses of a pair (0 for all-pairs)
};

/// evo_rpe's default: over the associated poses k = 0, delta, 2 delta, ... (evo's
/// non-overlapping pairs), E = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j) with Q ground truth and P estimate,
/// j = i + delta; no alignment. `delta` counts associated poses, not raw frame numbers.
RpeResult ComputeRpePerFrame(const Trajectory& gt, const Trajectory& est, int delta = 1,
                             const AssociationOptions& association = {});

/// The TUM evaluate_rpe.py protocol: E over all ordered pairs (i, j), i ≠ j, of associated
/// poses; when there are more than `max_pairs`, `max_pairs` pairs drawn uniformly (with
/// replacement) by std::mt19937(seed), so results are reproducible on every platform.
/// (TUM's script also counts the zero-error pairs i = j; we do not.)
RpeResult ComputeRpeAllPairs(const Trajectory& gt, const Trajectory& est, size_t max_pairs = 10000,
                             uint32_t seed = 42, const AssociationOptions& association = {});

/// KITTI odometry devkit errors: for every 10th first frame and each length 100, 200, ..., 800 m
/// of ground-truth path, pose_error = (P_f⁻¹ P_l)⁻¹ (Q_f⁻¹ Q_l) with l the first frame whose
/// path length exceeds the first frame's by more than the length. t_rel = mean ‖trans‖ / length
/// in percent, r_rel = mean angle / length in degrees per metre. `defined` is false (and the
/// figures NaN) when the ground-truth path is shorter than 100 m.
struct KittiSegmentError {
  double t_rel_percent, r_rel_deg_per_m;
  size_t segments;
  bool defined;
};

KittiSegmentError ComputeKittiSegmentErrors(const Trajectory& gt, const Trajectory& est,
                                            const AssociationOptions& association = {});

/// Summed distance between consecutive positions, metres.
double PathLength(const Trajectory& trajectory);

/// `est` with every position mapped by `s` (s R p + t) and rotations by R: the estimate in the
/// ground truth's frame and scale.
Trajectory ApplySim3(const Sim3& s, const Trajectory& est);

}  // namespace cslam
