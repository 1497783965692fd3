#pragma once
// metrics.json of a run (docs/formats.md): one struct per JSON object, every number optional —
// an unknown or unavailable figure is written as JSON null. Each struct's field table (below
// the structs) is the one description the writer and the reader share: a new metric is a
// member and its row.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "system/eval/json_fields.h"

namespace cslam {

/// The contents of metrics.json; field names are the JSON keys.
struct RunMetrics {
  /// Camera trajectory errors (metres, radians). RPE: RMSE; per-frame delta = 1 frame,
  /// all-pairs over ≤ 10 000 random ordered pairs (seed 42).
  struct Camera {
    std::optional<double> ate_m, ate_sim3_m, sim3_scale;
    std::optional<double> rpe_frame_t_m, rpe_frame_r_rad, rpe_pairs_t_m, rpe_pairs_r_rad;
    std::optional<double> path_length_m, gt_path_length_m;

    bool operator==(const Camera&) const = default;
  };
  /// One ground-truth object and the cluster matched to it (if any).
  struct PerObject {
    int gt_object = -1;
    std::optional<int> cluster;
    std::optional<int> landmarks;
    std::optional<double> ate_m, rpe_frame_t_m, rpe_frame_r_rad, rpe_pairs_t_m, rpe_pairs_r_rad;
    /// Own Sim(3) alignment; and the error as the camera sees it, which neither the camera's
    /// drift nor the ground truth's world enters (system/eval/object_camera_frame_error.h).
    std::optional<double> ate_sim3_m, camera_frame_rmse_m;
    /// Motion error per frame (system/eval/object_motion_error.h): means over the object's
    /// consecutive tracked frames of the rotation (degrees) and translation (metres) error of
    /// its frame-to-frame motion, the largest rotation error, and how many frame pairs.
    std::optional<double> me_r_deg, me_t_m, me_max_r_deg;
    std::optional<int> me_pairs;
    /// Median distance from the true camera to the true object over its labelled frames (m).
    std::optional<double> median_distance_m;
    bool found = false;

    bool operator==(const PerObject&) const = default;
  };
  /// Found objects whose median distance lies in (from_m, to_m] (from 0 inclusive; to_m empty:
  /// no bound).
  struct DistanceBand {
    double from_m = 0;
    std::optional<double> to_m;
    int found = 0;
    std::optional<double> me_r_deg, me_t_m, ate_m;

    bool operator==(const DistanceBand&) const = default;
  };
  /// Object trajectory errors averaged over matched objects, each aligned on its own.
  struct Objects {
    std::optional<double> ate_m, rpe_frame_t_m, rpe_frame_r_rad, rpe_pairs_t_m, rpe_pairs_r_rad;
    std::optional<double> ate_sim3_m, camera_frame_rmse_m;
    /// Means over found objects of their motion errors (PerObject::me_*), and their medians.
    std::optional<double> me_r_deg, me_t_m, me_r_deg_median, me_t_m_median;
    /// The same means by the objects' median distance: ≤ 20 m, 20–40 m, > 40 m.
    std::vector<DistanceBand> distance_bands;
    /// Needs no ground truth: the largest rotation between consecutive poses of any reported
    /// object (degrees), and that object's id and the later frame.
    std::optional<double> max_frame_rotation_deg;
    std::optional<int> max_frame_rotation_object, max_frame_rotation_frame;
    std::optional<int> matched, gt;
    /// Objects with at least `eligible_min_landmarks` clusterable landmarks (PerObject::
    /// landmarks), and how many of those were found: the "every object with ≥ 30 tracked
    /// landmarks found" figure, which objects a few points wide cannot spoil.
    std::optional<int> eligible, found_eligible, eligible_min_landmarks;
    /// Moving clusters reported as objects (system/map/object_report.h), with or without labels.
    std::optional<int> reported;
    /// Where landmarks are labelled: reported objects most of whose labelled landmarks lie on
    /// one moving object; precision = that / reported; recall = matched / gt.
    std::optional<int> reported_on_movers;
    std::optional<double> precision, recall;
    /// Static landmarks (on no moving object) that sit in a reported object / static landmarks.
    std::optional<double> static_in_objects_fraction;
    std::vector<PerObject> per_object;

    bool operator==(const Objects&) const = default;
  };
  /// Clustering against ground-truth labels; vi in nats (natural logarithm).
  struct Clustering {
    std::optional<double> accuracy, vi;
    std::optional<int> clusters, gt_objects;

    bool operator==(const Clustering&) const = default;
  };
  /// Landmark position RMSE over all (landmark, frame) pairs, metres.
  struct Landmarks {
    std::optional<double> rmse_m;
    std::optional<long long> count;

    bool operator==(const Landmarks&) const = default;
  };
  /// The static landmarks' whitened reprojection residuals under the final camera poses
  /// (system/eval/noise_check.h): chi2_per_dof ≈ 1 when the keypoint covariances are honest.
  struct Noise {
    std::optional<double> static_chi2_per_dof, static_cut_fraction;
    std::optional<int> static_landmarks;
    std::optional<long long> static_observations;

    bool operator==(const Noise&) const = default;
  };
  /// Wall-clock figures.
  struct Timing {
    std::optional<double> total_s, frontend_ms_per_frame, backend_ms_per_window, hz;
    /// The process's peak resident set size, MiB (getrusage ru_maxrss), taken when the
    /// metrics are written: the run's own figure, whatever ran it.
    std::optional<double> peak_rss_mb;

    bool operator==(const Timing&) const = default;
  };
  /// How the run went (docs/reliability.md): what was cut short, discarded or chained blindly.
  struct Status {
    bool interrupted = false;            ///< stopped by SIGINT/SIGTERM before the end
    int windows = 0;                     ///< backend windows run
    std::vector<int> failed_windows;     ///< first frame of each discarded window
    /// first frame of each window integrated without its bundle adjustment (not usable)
    std::vector<int> adjustment_failed_windows;
    std::vector<int> tracking_lost;      ///< frames where the frontend lost every track
    std::vector<int> gaps;               ///< frames where the trajectory was chained without overlap

    bool operator==(const Status&) const = default;
  };

  /// The run's self-calibration (calibration.estimate_disparity_offset); empty when off.
  struct Calibration {
    std::optional<double> disparity_offset_px;        ///< δ estimated
    std::optional<double> disparity_offset_sigma_px;  ///< its standard deviation
    std::optional<double> disparity_offset_applied_px;  ///< δ applied (0: not significant)
    std::optional<int> disparity_offset_frames;       ///< frames it was estimated over
    /// Largest yaw rate of the camera in those frames, rad/s (+ = left; PeakYawRate).
    std::optional<double> disparity_offset_yaw_rate;
    std::optional<std::string> disparity_offset_decision;  ///< why δ was or was not applied

    bool operator==(const Calibration&) const = default;
  };

  /// How far the ground truth itself can be trusted, where the dataset says (KITTI raw): the
  /// device's median stated position accuracy, and its second estimate of the camera path
  /// (GroundTruthCrossCheck) against the ground truth and against the estimate. An ATE against
  /// the ground truth well below cross_check_ate_sim3_m measures the reference, not the method.
  struct GroundTruthCheck {
    std::optional<std::string> cross_check;  ///< what the second estimate is
    std::optional<double> position_accuracy_median_m;
    std::optional<double> cross_check_path_length_m;
    std::optional<double> cross_check_ate_sim3_m;   ///< second estimate vs the ground truth
    std::optional<double> camera_ate_sim3_vs_cross_check_m;  ///< the run's camera vs the second estimate
    std::optional<double> camera_sim3_scale_vs_cross_check;

    bool operator==(const GroundTruthCheck&) const = default;
  };

  std::string sequence;
  std::optional<int> frames;
  std::string method;
  Camera camera;
  Objects objects;
  Clustering clustering;
  Landmarks landmarks;
  Noise noise;
  std::optional<double> log_chi2;
  Timing timing;
  Status run;
  Calibration calibration;
  GroundTruthCheck ground_truth;

  bool operator==(const RunMetrics&) const = default;
};

// The field tables: JSON key, member. The keys are the member names.

template <>
struct JsonFields<RunMetrics::Camera> {
  using S = RunMetrics::Camera;
  static constexpr auto kFields = std::tuple{
      JsonField{"ate_m", &S::ate_m},
      JsonField{"ate_sim3_m", &S::ate_sim3_m},
      JsonField{"sim3_scale", &S::sim3_scale},
      JsonField{"rpe_frame_t_m", &S::rpe_frame_t_m},
      JsonField{"rpe_frame_r_rad", &S::rpe_frame_r_rad},
      JsonField{"rpe_pairs_t_m", &S::rpe_pairs_t_m},
      JsonField{"rpe_pairs_r_rad", &S::rpe_pairs_r_rad},
      JsonField{"path_length_m", &S::path_length_m},
      JsonField{"gt_path_length_m", &S::gt_path_length_m},
  };
};

template <>
struct JsonFields<RunMetrics::PerObject> {
  using S = RunMetrics::PerObject;
  static constexpr auto kFields = std::tuple{
      JsonField{"gt_object", &S::gt_object},
      JsonField{"cluster", &S::cluster},
      JsonField{"landmarks", &S::landmarks},
      JsonField{"ate_m", &S::ate_m},
      JsonField{"ate_sim3_m", &S::ate_sim3_m},
      JsonField{"camera_frame_rmse_m", &S::camera_frame_rmse_m},
      JsonField{"rpe_frame_t_m", &S::rpe_frame_t_m},
      JsonField{"rpe_frame_r_rad", &S::rpe_frame_r_rad},
      JsonField{"rpe_pairs_t_m", &S::rpe_pairs_t_m},
      JsonField{"rpe_pairs_r_rad", &S::rpe_pairs_r_rad},
      JsonField{"me_r_deg", &S::me_r_deg},
      JsonField{"me_t_m", &S::me_t_m},
      JsonField{"me_max_r_deg", &S::me_max_r_deg},
      JsonField{"me_pairs", &S::me_pairs},
      JsonField{"median_distance_m", &S::median_distance_m},
      JsonField{"found", &S::found},
  };
};

template <>
struct JsonFields<RunMetrics::DistanceBand> {
  using S = RunMetrics::DistanceBand;
  static constexpr auto kFields = std::tuple{
      JsonField{"from_m", &S::from_m},
      JsonField{"to_m", &S::to_m},
      JsonField{"found", &S::found},
      JsonField{"me_r_deg", &S::me_r_deg},
      JsonField{"me_t_m", &S::me_t_m},
      JsonField{"ate_m", &S::ate_m},
  };
};

template <>
struct JsonFields<RunMetrics::Objects> {
  using S = RunMetrics::Objects;
  static constexpr auto kFields = std::tuple{
      JsonField{"ate_m", &S::ate_m},
      JsonField{"ate_sim3_m", &S::ate_sim3_m},
      JsonField{"camera_frame_rmse_m", &S::camera_frame_rmse_m},
      JsonField{"rpe_frame_t_m", &S::rpe_frame_t_m},
      JsonField{"rpe_frame_r_rad", &S::rpe_frame_r_rad},
      JsonField{"rpe_pairs_t_m", &S::rpe_pairs_t_m},
      JsonField{"rpe_pairs_r_rad", &S::rpe_pairs_r_rad},
      JsonField{"me_r_deg", &S::me_r_deg},
      JsonField{"me_t_m", &S::me_t_m},
      JsonField{"me_r_deg_median", &S::me_r_deg_median},
      JsonField{"me_t_m_median", &S::me_t_m_median},
      JsonField{"distance_bands", &S::distance_bands},
      JsonField{"max_frame_rotation_deg", &S::max_frame_rotation_deg},
      JsonField{"max_frame_rotation_object", &S::max_frame_rotation_object},
      JsonField{"max_frame_rotation_frame", &S::max_frame_rotation_frame},
      JsonField{"matched", &S::matched},
      JsonField{"gt", &S::gt},
      JsonField{"eligible", &S::eligible},
      JsonField{"found_eligible", &S::found_eligible},
      JsonField{"eligible_min_landmarks", &S::eligible_min_landmarks},
      JsonField{"reported", &S::reported},
      JsonField{"reported_on_movers", &S::reported_on_movers},
      JsonField{"precision", &S::precision},
      JsonField{"recall", &S::recall},
      JsonField{"static_in_objects_fraction", &S::static_in_objects_fraction},
      JsonField{"per_object", &S::per_object},
  };
};

template <>
struct JsonFields<RunMetrics::Clustering> {
  using S = RunMetrics::Clustering;
  static constexpr auto kFields = std::tuple{
      JsonField{"accuracy", &S::accuracy},
      JsonField{"vi", &S::vi},
      JsonField{"clusters", &S::clusters},
      JsonField{"gt_objects", &S::gt_objects},
  };
};

template <>
struct JsonFields<RunMetrics::Landmarks> {
  using S = RunMetrics::Landmarks;
  static constexpr auto kFields = std::tuple{
      JsonField{"rmse_m", &S::rmse_m},
      JsonField{"count", &S::count},
  };
};

template <>
struct JsonFields<RunMetrics::Noise> {
  using S = RunMetrics::Noise;
  static constexpr auto kFields = std::tuple{
      JsonField{"static_chi2_per_dof", &S::static_chi2_per_dof},
      JsonField{"static_cut_fraction", &S::static_cut_fraction},
      JsonField{"static_landmarks", &S::static_landmarks},
      JsonField{"static_observations", &S::static_observations},
  };
};

template <>
struct JsonFields<RunMetrics::Timing> {
  using S = RunMetrics::Timing;
  static constexpr auto kFields = std::tuple{
      JsonField{"total_s", &S::total_s},
      JsonField{"frontend_ms_per_frame", &S::frontend_ms_per_frame},
      JsonField{"backend_ms_per_window", &S::backend_ms_per_window},
      JsonField{"hz", &S::hz},
      JsonField{"peak_rss_mb", &S::peak_rss_mb},
  };
};

template <>
struct JsonFields<RunMetrics::Status> {
  using S = RunMetrics::Status;
  static constexpr auto kFields = std::tuple{
      JsonField{"interrupted", &S::interrupted},
      JsonField{"windows", &S::windows},
      JsonField{"failed_windows", &S::failed_windows},
      JsonField{"adjustment_failed_windows", &S::adjustment_failed_windows},
      JsonField{"tracking_lost", &S::tracking_lost},
      JsonField{"gaps", &S::gaps},
  };
};

template <>
struct JsonFields<RunMetrics::Calibration> {
  using S = RunMetrics::Calibration;
  static constexpr auto kFields = std::tuple{
      JsonField{"disparity_offset_px", &S::disparity_offset_px},
      JsonField{"disparity_offset_sigma_px", &S::disparity_offset_sigma_px},
      JsonField{"disparity_offset_applied_px", &S::disparity_offset_applied_px},
      JsonField{"disparity_offset_frames", &S::disparity_offset_frames},
      JsonField{"disparity_offset_yaw_rate", &S::disparity_offset_yaw_rate},
      JsonField{"disparity_offset_decision", &S::disparity_offset_decision},
  };
};

template <>
struct JsonFields<RunMetrics::GroundTruthCheck> {
  using S = RunMetrics::GroundTruthCheck;
  static constexpr auto kFields = std::tuple{
      JsonField{"cross_check", &S::cross_check},
      JsonField{"position_accuracy_median_m", &S::position_accuracy_median_m},
      JsonField{"cross_check_path_length_m", &S::cross_check_path_length_m},
      JsonField{"cross_check_ate_sim3_m", &S::cross_check_ate_sim3_m},
      JsonField{"camera_ate_sim3_vs_cross_check_m", &S::camera_ate_sim3_vs_cross_check_m},
      JsonField{"camera_sim3_scale_vs_cross_check", &S::camera_sim3_scale_vs_cross_check},
  };
};

template <>
struct JsonFields<RunMetrics> {
  using S = RunMetrics;
  static constexpr auto kFields = std::tuple{
      JsonField{"sequence", &S::sequence},
      JsonField{"frames", &S::frames},
      JsonField{"method", &S::method},
      JsonField{"camera", &S::camera},
      JsonField{"objects", &S::objects},
      JsonField{"clustering", &S::clustering},
      JsonField{"landmarks", &S::landmarks},
      JsonField{"noise", &S::noise},
      JsonField{"log_chi2", &S::log_chi2},
      JsonField{"timing", &S::timing},
      JsonField{"run", &S::run},
      JsonField{"calibration", &S::calibration},
      JsonField{"ground_truth", &S::ground_truth},
  };
};

/// The JSON document: the keys above, plus "conventions" naming each metric's statistic,
/// delta and logarithm base (implementations differ; readers should not have to guess).
nlohmann::json ToJson(const RunMetrics& metrics);

/// Inverse of ToJson (missing keys and nulls keep their defaults). Throws InputError(source)
/// naming the key when a present value has the wrong type.
RunMetrics RunMetricsFromJson(const nlohmann::json& json,
                              const std::string& source = "metrics.json");

/// Writes ToJson(metrics), indented, atomically to `path`.
void WriteMetricsJson(const RunMetrics& metrics, const std::string& path);

}  // namespace cslam
