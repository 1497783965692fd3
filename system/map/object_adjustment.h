#pragma once
// The end-of-run adjustment of one object: its poses at the frames its kept keypoints saw it
// and its landmarks' places in its body frame, fitted together to those keypoints (stereo
// reprojection, each keypoint with its covariance, Cauchy-robust) under the motion model of the
// track smoother (a white acceleration and a white angular acceleration between consecutive
// poses, and a velocity along one direction of travel in the body frame), as the field's object
// factor graphs do. One frame's keypoints place a far body only to a metre and turn it only to
// degrees, and the windows' shape of it can be 10 % off; all frames together, with what a
// vehicle can do between them, pin both. A vehicle moves where it points: a far car whose
// keypoints hardly fix its heading was fitted turning 3–5° per frame while its path ran
// straight, and its path fixes the direction it drives in.
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/task_runner.h"
#include "system/map/track_smoother.h"

namespace cslam {

/// One keypoint of the object: frame, the landmark's index into the places, (uL, vL, uR) px
/// and its covariance (px²).
struct ObjectKeypoint {
  int frame = 0;
  int landmark = 0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
};

/// The windows' turn of the body between two frames (world, left: R_to R_fromᵀ) and its
/// covariance (rad²): a bundle adjustment's relative rotation, which keeps a far body whose
/// keypoints hardly fix its heading from being fitted spinning.
struct ObjectTurn {
  int from_frame = 0, to_frame = 0;
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
};

/// What the adjustment did.
struct ObjectAdjustment {
  bool adjusted = false;  ///< false: poses and places are as given
  int frames = 0;         ///< poses adjusted
  int stretches = 0;      ///< stretches fitted (frames tied together by their landmarks)
  int keypoints = 0;
  int inliers = 0;  ///< keypoints the fit explains (χ²₃ 99.9 % at the scaled covariances)
  /// The fit turned the body or changed its velocity between two frames by more than the
  /// motion model allows (χ²₃ 99.9 %), and was not kept.
  bool implausible = false;
  /// Where: the frame, the turn (rad) or velocity change (m/s) found there, and its bound.
  int implausible_frame = -1;
  bool implausible_turn = false;
  double implausible_value = 0, implausible_bound = 0;
  /// The factor the keypoints' covariances were scaled by: their median squared residual
  /// over its χ²₃ median, when above 1 (a real frontend's covariances run small).
  double keypoint_scale = 1;
  /// Per place (adjusted fits only): whether most of its keypoints fit (the χ²₃ 99.9 % gate).
  /// A place that does not is left as given: it is not of this rigid body (a far static
  /// point taken in by a window), and fitted with the body it ran off towards infinity,
  /// where a point's image stays put however the body moves.
  std::vector<bool> explained;
};

/// Adjusts `world_from_body` at the frames with at least 3 of `keypoints` (and `turns`
/// between two such frames, Cauchy-robust) and every place in `in_body`, stretch by stretch:
/// a stretch ends where fewer than 3 landmarks were seen both before and after, and its first
/// pose is held (the first stretch's fixes the body frame; a later one's is where the track
/// carried the body across). Frames without enough keypoints take the correction of the
/// adjusted frames about them. `world_from_cam` is the map's camera (frames without a
/// pose are left alone); `time_of` gives a frame's time. The result is kept only when the
/// solver converged to a lower cost, explains at least half of the keypoints and moves the body
/// as the motion model allows between every two frames; places whose keypoints it does not
/// explain keep their given values. The fit's starts run through `runner` (one after another
/// without it).
ObjectAdjustment AdjustObject(const std::vector<ObjectKeypoint>& keypoints,
                              const std::vector<ObjectTurn>& turns,
                              std::vector<Eigen::Vector3d>* in_body,
                              std::map<int, Pose>* world_from_body,
                              const std::vector<std::optional<Pose>>& world_from_cam,
                              const StereoCamera& camera, const std::function<double(int)>& time_of,
                              const TrackSmootherOptions& motion,
                              const TaskRunner* runner = nullptr);

}  // namespace cslam
