#pragma once
// Is a new moving cluster an object seen before, back from behind an occluder? A car that
// drives behind a parked van loses every track and comes back on new ones; the windows then
// find it as a new cluster that shares no frame with the old one, so neither the motion test
// nor the place test (system/map/motion_agreement.h, co_location.h) can join them. The old
// body's motion, carried on at constant velocity over the gap, says where it can be when the
// new cluster appears: within the old body's and the new one's extents, the prediction's own
// uncertainty (from how well constant velocity fits the old track, at 99 %), and what a
// bounded acceleration adds over the gap (½ a t²); and its speed can have changed by a t at
// most. Centres and extents are medians: a window's few mislabelled points must not move them.
#include <map>
#include <vector>

#include "core/rigid.h"

namespace cslam {

/// What a reappearance may bridge.
struct ReappearanceGate {
  double frame_period_s = 0.1;         ///< time between frames
  double max_gap_s = 3.0;              ///< longest gap bridged (0: off)
  double max_acceleration_mps2 = 3.0;  ///< |a| a road vehicle keeps up over a gap
  int fit_frames = 10;                 ///< last poses of the old track the prediction fits
  int compare_frames = 10;             ///< first poses of the new track compared with it
};

/// The old cluster `a` carried over the gap to the new cluster `b`.
struct Reappearance {
  int gap_frames = 0;  ///< b's first posed frame − a's last (0: they overlap or touch nothing)
  int compared = 0;    ///< b's frames compared (0: not compared)
  /// |b's centre − a's predicted centre| at b's first frame, from lines fitted to each track.
  double distance_m = 0;
  /// What a's body could have reached: both bodies' extents (median distances of their points
  /// from their centres), ½ a t² over the gap and 99 % of the two lines' uncertainties there.
  double allowed_m = 0;
  /// b's frame in a's: b's centre on a's (b's points say where the body is far better than a
  /// prediction over the gap), turned as a's predicted turn says. Set only when Reachable().
  Pose a_from_b = Pose::Identity();
  /// |b's velocity over its first frames − a's over its last| (the lines' slopes) and what the
  /// acceleration allows between the middles of the two fits, plus 99 % of their uncertainty.
  double speed_change_mps = 0;
  double allowed_speed_change_mps = 0;
  /// Both deviations against their bounds, (d / allowed)² + (Δv / allowed Δv)²: each bound is
  /// a 99 % one of a 3-D error, and a new body near the edge of both at once is far less
  /// likely than near one, so they are tested jointly, as a 6-D χ² at 99 % would.
  double Score() const;
  /// The parts of allowed_m and allowed_speed_change_mps that are the tracks' uncertainty.
  double uncertainty_m = 0, uncertainty_mps = 0;
  /// Whether the tracks are precise enough to tell: neither bound is mostly uncertainty (at
  /// most half of it). A gate whose width is mostly noise lets through whatever passes by; a
  /// missed re-identification costs an id, a wrong one corrupts a trajectory.
  bool Precise() const;
  /// compared, Precise() and Score() within the joint bound.
  bool Reachable() const;
};

/// Whether b starts after a ends, within gate.max_gap_s (false when the test is off): the
/// cheap part of CompareAcrossGap, for callers to skip gathering points for pairs it refuses.
bool WithinGap(const std::map<int, Pose>& world_from_a, const std::map<int, Pose>& world_from_b,
               const ReappearanceGate& gate);

/// Compares a's track, carried on past its last pose, with the first gate.compare_frames poses
/// of b (which starts after a ends, within gate.max_gap_s). compared == 0 when they overlap in
/// time, the gap is too long, a has fewer than 3 poses, b fewer than compare_frames, or a side
/// has no point.
Reappearance CompareAcrossGap(const std::map<int, Pose>& world_from_a,
                              const std::vector<Eigen::Vector3d>& points_in_a,
                              const std::map<int, Pose>& world_from_b,
                              const std::vector<Eigen::Vector3d>& points_in_b,
                              const ReappearanceGate& gate);

}  // namespace cslam
