#pragma once
// The stereo frontend: per rectified grey stereo pair, tracks the live tracklets into the new
// left image (KLT + forward-backward + NCC), matches every point into the right image on its
// row (ORB + 1-D NCC refinement), re-detects in emptied grid cells and appends the stereo
// observations, each with a 3×3 pixel covariance, to the TrackletTable. No ego-motion
// outlier rejection: tracks on moving objects are kept (docs/frontend.md).
#include <memory>
#include <opencv2/core/mat.hpp>

#include "core/stereo_camera.h"
#include "frontend/grid_detector.h"
#include "frontend/keypoint_covariance.h"
#include "frontend/klt_tracker.h"
#include "frontend/stereo_matcher.h"

namespace cslam {

class OptionsReader;
class TaskRunner;
class TrackletTable;

/// Options of the whole frontend; each component's options are a YAML section of the same name.
struct FrontendOptions {
  GridDetectorOptions detector;
  KltTrackerOptions tracker;
  StereoMatcherOptions stereo;
  KeypointCovarianceOptions covariance;
  /// Write a new track to the table only once it is tracked (with stereo) into the next
  /// frame, so single-frame landmarks never reach the backend.
  bool confirm_new_tracks = true;
  /// Seed KLT with the track's last image motion (a per-track constant-velocity guess; it
  /// never rejects anything).
  bool predict_flow = true;
  /// Search a tracked point's stereo match near its last disparity (StereoMatcherOptions::
  /// prior_margin_*) instead of over the whole range.
  bool use_disparity_prior = true;
  /// Tracking loss: when fewer tracks than this, and under a tenth of the live ones, survive
  /// into a frame (a jump, a black frame), the survivors are likely false matches: they are
  /// dropped and tracking starts over from new detections. 0 = only when none survive.
  int reinit_below_tracks = 10;
  /// A keypoint whose structure-tensor window (covariance.window_px) holds a pixel at or above
  /// this grey level, in the left image or at its match in the right one, is marked clipped
  /// (StereoObservation::clipped): where a bright surface saturates, the corner's position
  /// follows each camera's exposure, so the moving test does not take it as evidence of
  /// motion. Above 255 = never.
  int clipped_grey = 250;
  /// Runs the stereo match's parts side by side (null: on the caller's thread). Not read from
  /// YAML: system/ supplies it, since threads belong there; outputs do not depend on it.
  std::shared_ptr<const TaskRunner> runner;

  void Check() const;
  /// Reads the fields and the sections detector, tracker, stereo, covariance (each finished).
  void Load(OptionsReader& reader);
};

/// What happened in one frame; times are wall-clock milliseconds.
struct FrameSummary {
  int frame = -1;
  int tracked = 0;          ///< live tracks continued into this frame (with a stereo match)
  int created = 0;          ///< new tracks started this frame (detected and stereo-matched)
  int lost = 0;             ///< tracks that ended this frame (tracking or stereo failure)
  int stereo_rejected = 0;  ///< of the tracked and new points, those without a stereo match
  int lost_in_stereo = 0;   ///< of `lost`, tracked points ended by a failed stereo match
  int detected = 0;         ///< new corners detected before the stereo match
  int new_landmarks = 0;    ///< landmark ids created in the table this frame
  int observations = 0;     ///< observations appended to the table this frame
  /// Tracking was lost: the previous frame had live tracks and none continued into this one
  /// (a black or textureless frame, a jump). The frontend starts over from new detections;
  /// the pipeline starts its windows after such a break (docs/reliability.md).
  bool tracking_lost = false;
  // Per stage: wall-clock ms (what a caller waits) and the calling thread's CPU ms (what the
  // stage costs, unaffected by other processes competing for the core).
  double track_ms = 0, cpu_track_ms = 0;            ///< pyramid + KLT forward-backward + NCC
  double detect_ms = 0, cpu_detect_ms = 0;          ///< grid FAST detection
  double stereo_ms = 0, cpu_stereo_ms = 0;          ///< row search, refinement, checks
  double covariance_ms = 0, cpu_covariance_ms = 0;  ///< covariances and table writes
  double total_ms = 0, cpu_total_ms = 0;
};

/// Stateful frontend for one camera stream. Not thread-safe; one instance per stream.
class StereoFrontend {
 public:
  /// Throws ConfigError when the camera or the options are not usable.
  StereoFrontend(const StereoCamera& camera, const FrontendOptions& options);
  ~StereoFrontend();
  StereoFrontend(StereoFrontend&&) noexcept;
  StereoFrontend& operator=(StereoFrontend&&) noexcept;

  /// Tracks live tracklets into this frame, matches them in the right image, detects new
  /// ones; appends observations for `frame` to `table`. Images are rectified CV_8UC1 of the
  /// camera's size (throws InputError otherwise); they are not retained after the call.
  /// Frame indices must increase between calls (a broken invariant aborts); Reset() lifts it.
  FrameSummary Process(int frame, const cv::Mat& left_grey, const cv::Mat& right_grey,
                       TrackletTable* table);
  /// Drops all live tracks (tracking loss / re-initialisation).
  void Reset();
  /// Number of live tracks after the last Process (confirmed and unconfirmed).
  int num_live_tracks() const;

 private:
  struct State;
  StereoCamera camera_;
  FrontendOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace cslam
