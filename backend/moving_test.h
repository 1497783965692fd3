#pragma once
// Is a cluster an independently moving body? [ours, for real images]
//
// A likelihood-ratio test with the keypoint covariances: the cluster's landmark tracks
// (camera-frame back-projections X_t with covariance Σ_t) are mapped once by the static
// world's camera poses and once by the cluster's own motion. Under either model a landmark's
// mapped samples should be one point; its χ² about their information-weighted mean is the
// model's misfit. The cluster's own motion has 6 more unknowns per frame than the static world
// (fewer where it holds fewer than two landmarks, minus the 6 of its frame's gauge), so if the
// cluster is static, χ²_static − χ²_own is χ²-distributed with that many degrees of freedom.
// The cluster is called moving only when the difference exceeds the (1 − false_alarm)
// quantile: its own 6 DoF per frame over-fitting noise does not pass, and neither do far or
// low-parallax landmarks, whose wide depth covariance leaves little χ² to explain.
//
// Each sample's χ² is capped at `sample_gate_chi2` under both models (truncated least
// squares): one KLT jump or a track that slid along an occlusion edge adds at most the cap to
// either sum instead of deciding the test alone.
//
// Both models also get one nuisance unknown, a disparity offset δ shared by the cluster's
// observations (bounded by `max_disparity_offset_px`). Real rectified pairs carry one that
// the calibration does not state, and a left/right exposure offset in a turn acts like one:
// it moves every point along its ray by z² δ / (f b), so as the camera approaches a far
// static piece its points seem to slide, and the piece's own motion would absorb that.
// A moving body is not explained by δ: it moves the same however far its points are.
//
// The keypoint covariances describe independent noise; the errors that move a group of
// neighbouring tracks alike (a rectification residual where the group crosses the image,
// KLT drift on a shared texture) are not in them, and the clustering finds exactly such
// groups among the tracks that fit the static world worst. Each sample's covariance gets a
// floor of `model_error_px` in every pixel coordinate for this test, so a group is called
// moving only when its motion shows by more than such errors.
//
// Samples the frontend marked clipped (StereoObservation::clipped: saturated pixels in the
// keypoint's window) do not enter the test. Where a bright surface saturates, a corner on its
// edge moves with each camera's exposure, and every corner along that edge moves alike: on
// KITTI raw 0005 such groups on a sunlit road became "moving" objects.
#include <functional>
#include <vector>

#include "backend/point_tracks.h"
#include "core/options_reader.h"
#include "core/rigid.h"

namespace cslam {

/// Thresholds of the moving-or-static test.
struct MovingTestOptions {
  /// Probability that a static cluster passes as moving when the covariances are right.
  double false_alarm = 1e-4;
  /// χ²(3) 0.999: a sample contributes at most this much to either model's χ².
  double sample_gate_chi2 = 16.27;
  /// Bound of the nuisance disparity offset (px) of both models; 0 = no nuisance.
  double max_disparity_offset_px = 1.0;
  /// σ (px, each image coordinate) of the errors the keypoint covariances leave out because
  /// they do not average out along a track: rectification residuals and KLT drift, which
  /// move neighbouring tracks alike. Added to every sample's covariance in this test only.
  double model_error_px = 3.0;

  void Check() const;
  void Load(OptionsReader& reader);
  bool operator==(const MovingTestOptions&) const = default;
};

/// The test's sums and verdict.
struct MovingTestResult {
  double chi2_static = 0.0;  ///< capped χ² of the landmarks under the static world's motion
  double chi2_own = 0.0;     ///< ... under the cluster's own motion
  int landmarks = 0;         ///< landmarks with at least 2 samples both models cover
  int frames = 0;            ///< distinct frames of those samples
  int dof = 0;               ///< the own motion's extra unknowns (see the file comment)
  double threshold = 0.0;    ///< χ²(dof) quantile at 1 − false_alarm
  double offset_static_px = 0.0;  ///< the nuisance disparity offset fitted under each model
  double offset_own_px = 0.0;
  bool moving = false;       ///< chi2_static − chi2_own > threshold

  double Statistic() const { return chi2_static - chi2_own; }
};

/// Maps a camera-frame point at `frame` into a model's frame; nullptr where the model has no
/// pose at that frame.
using ModelPose = std::function<const Pose*(int frame)>;

/// Capped χ² of one track about its information-weighted mean under `model`, over the samples
/// at frames where `covered(frame)` holds, with every disparity read `offset_px` smaller;
/// `used` (may be null) receives their count. 0 with fewer than 2 samples.
double CappedTrackChi2(const PointTrack& track, const ModelPose& model,
                       const std::function<bool(int)>& covered, double gate_chi2, int* used,
                       double offset_px = 0.0, double model_error_px = 0.0);

/// The disparity offset (px, within ±max_offset_px) that minimises the tracks' χ² under
/// `model` over the samples within `gate_chi2` of their track's mean; 0 where the samples
/// carry no disparity.
double FitDisparityOffset(const std::vector<const PointTrack*>& tracks, const ModelPose& model,
                          const std::function<bool(int)>& covered, double gate_chi2,
                          double max_offset_px, double model_error_px = 0.0);

/// The test of `tracks` (one cluster's landmarks) under `static_model` (cam → world) against
/// `own_model` (cam → cluster), over the frames where both have a pose.
MovingTestResult TestMoving(const std::vector<const PointTrack*>& tracks,
                            const ModelPose& static_model, const ModelPose& own_model,
                            const MovingTestOptions& options);

/// Upper quantile: x with P(χ²(dof) > x) = p (Wilson–Hilferty; relative error < 1 % for
/// dof ≥ 3 and p ≥ 1e-6). dof > 0, 0 < p < 1.
double ChiSquareUpperQuantile(double dof, double p);

}  // namespace cslam

