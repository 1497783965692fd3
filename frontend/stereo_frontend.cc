#include "frontend/stereo_frontend.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/logging.h"
#include "core/options_reader.h"
#include "core/timer.h"
#include "core/tracklet_table.h"

namespace cslam {

void FrontendOptions::Check() const {
  CheckSection("detector", [&] { detector.Check(); });
  CheckSection("tracker", [&] { tracker.Check(); });
  CheckSection("stereo", [&] { stereo.Check(); });
  CheckSection("covariance", [&] { covariance.Check(); });
  CheckOption(reinit_below_tracks >= 0, "reinit_below_tracks", "must be >= 0", reinit_below_tracks);
  CheckOption(clipped_grey >= 1, "clipped_grey", "must be a grey level >= 1 (above 255: never)",
              clipped_grey);
}

void FrontendOptions::Load(OptionsReader& reader) {
  reader.Read("confirm_new_tracks", &confirm_new_tracks);
  reader.Read("predict_flow", &predict_flow);
  reader.Read("use_disparity_prior", &use_disparity_prior);
  reader.Read("reinit_below_tracks", &reinit_below_tracks);
  reader.Read("clipped_grey", &clipped_grey);
  reader.ReadSection("detector", &detector);
  reader.ReadSection("tracker", &tracker);
  reader.ReadSection("stereo", &stereo);
  reader.ReadSection("covariance", &covariance);
}

namespace {
// Whether the (2 half + 1)² window around `p` holds a pixel at or above `level`.
bool TouchesLevel(const cv::Mat& grey, cv::Point2f p, int half, int level) {
  if (level > 255) return false;
  const int cx = static_cast<int>(std::lround(p.x)), cy = static_cast<int>(std::lround(p.y));
  const int x0 = std::max(0, cx - half), x1 = std::min(grey.cols - 1, cx + half);
  const int y0 = std::max(0, cy - half), y1 = std::min(grey.rows - 1, cy + half);
  for (int y = y0; y <= y1; ++y) {
    const uchar* row = grey.ptr<uchar>(y);
    for (int x = x0; x <= x1; ++x)
      if (row[x] >= level) return true;
  }
  return false;
}

/// Wall-clock and thread-CPU stopwatch for the per-stage times of FrameSummary.
class StageClock {
 public:
  StageClock() { Reset(); }
  void Reset() {
    wall_.Reset();
    cpu_start_ = ThreadCpuMs();
  }
  /// Writes the time since the last Reset and resets.
  void Lap(double* wall_ms, double* cpu_ms) {
    *wall_ms = wall_.ElapsedMs();
    *cpu_ms = ThreadCpuMs() - cpu_start_;
    Reset();
  }

 private:
  static double ThreadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  }
  Timer wall_;
  double cpu_start_ = 0;
};

/// One live tracklet. landmark < 0 while it waits for confirmation; its first observation is
/// then held here instead of in the table.
struct Track {
  int landmark = -1;
  cv::Point2f pt;
  cv::Point2f flow{0, 0};
  int level = 0;
  float fb_error_px = 0;
  float disparity = 0;  ///< of the last stereo match, px
  int pending_frame = -1;
  Eigen::Vector3d pending_x;
  Eigen::Matrix3d pending_cov;
  bool pending_clipped = false;
};
}  // namespace

struct StereoFrontend::State {
  State(const FrontendOptions& o) : detector(o.detector), tracker(o.tracker), matcher(o.stereo) {}
  GridDetector detector;
  KltTracker tracker;
  StereoMatcher matcher;
  KltPyramid prev;
  bool has_prev = false;
  int last_frame = -1;
  std::vector<Track> tracks;
};

StereoFrontend::StereoFrontend(const StereoCamera& camera, const FrontendOptions& options)
    : camera_(camera), options_(options) {
  camera_.Check();
  options_.Check();
  state_ = std::make_unique<State>(options_);
}
StereoFrontend::~StereoFrontend() = default;
StereoFrontend::StereoFrontend(StereoFrontend&&) noexcept = default;
StereoFrontend& StereoFrontend::operator=(StereoFrontend&&) noexcept = default;

void StereoFrontend::Reset() {
  state_->tracks.clear();
  state_->prev = KltPyramid();
  state_->has_prev = false;
}

int StereoFrontend::num_live_tracks() const { return static_cast<int>(state_->tracks.size()); }

FrameSummary StereoFrontend::Process(int frame, const cv::Mat& left_grey, const cv::Mat& right_grey,
                                     TrackletTable* table) {
  CSLAM_CHECK(table != nullptr, "StereoFrontend::Process needs a table");
  const cv::Size expected(camera_.width, camera_.height);
  for (const cv::Mat* image : {&left_grey, &right_grey})
    if (image->type() != CV_8UC1 || image->size() != expected)
      throw InputError("frame " + std::to_string(frame),
                       "expected a " + std::to_string(camera_.width) + "x" +
                           std::to_string(camera_.height) + " 8-bit grey image, got " +
                           std::to_string(image->cols) + "x" + std::to_string(image->rows) +
                           " with " + std::to_string(image->channels()) + " channel(s)");
  State& s = *state_;
  // Tracks carry observations between frames; going back would write a landmark's frames out
  // of order.
  CSLAM_CHECK(!s.has_prev || frame > s.last_frame, "frames must be processed in increasing order");
  FrameSummary summary;
  summary.frame = frame;
  StageClock total;

  // 1. Temporal tracking of the live tracks.
  StageClock timer;
  KltPyramid cur = s.tracker.BuildPyramid(left_grey);
  std::vector<Track> tracks;
  const size_t live_before = s.has_prev ? s.tracks.size() : 0;
  if (s.has_prev && !s.tracks.empty()) {
    std::vector<cv::Point2f> prev_pts, predicted;
    prev_pts.reserve(s.tracks.size());
    predicted.reserve(s.tracks.size());
    for (const Track& t : s.tracks) {
      prev_pts.push_back(t.pt);
      predicted.push_back(options_.predict_flow ? t.pt + t.flow : t.pt);
    }
    const std::vector<TrackResult> results = s.tracker.Track(s.prev, cur, prev_pts, predicted);
    tracks.reserve(s.tracks.size());
    for (size_t i = 0; i < results.size(); ++i) {
      if (!results[i].ok()) {
        ++summary.lost;
        continue;
      }
      Track t = s.tracks[i];
      t.flow = results[i].pt - t.pt;
      t.pt = results[i].pt;
      t.fb_error_px = results[i].fb_error_px;
      tracks.push_back(t);
    }
  }
  if (live_before > 0 && static_cast<int>(tracks.size()) < options_.reinit_below_tracks &&
      10 * tracks.size() < live_before) {
    summary.lost += static_cast<int>(tracks.size());
    summary.tracking_lost = true;
    tracks.clear();
  }
  timer.Lap(&summary.track_ms, &summary.cpu_track_ms);

  // 2. Re-detection in the cells the surviving tracks leave empty.
  std::vector<cv::Point2f> points;
  points.reserve(tracks.size() + options_.detector.target_count);
  for (const Track& t : tracks) points.push_back(t.pt);
  const std::vector<DetectedKeypoint> detections = s.detector.Detect(left_grey, points);
  summary.detected = static_cast<int>(detections.size());
  for (const DetectedKeypoint& d : detections) points.push_back(d.pt);
  timer.Lap(&summary.detect_ms, &summary.cpu_detect_ms);

  // 3. Stereo match of every point, tracked and new.
  std::vector<float> priors(points.size(), 0.f);
  if (options_.use_disparity_prior)
    for (size_t i = 0; i < tracks.size(); ++i) priors[i] = tracks[i].disparity;
  const std::vector<StereoMatch> matches =
      s.matcher.Match(left_grey, right_grey, points, priors, options_.runner.get());
  timer.Lap(&summary.stereo_ms, &summary.cpu_stereo_ms);

  // 4. Covariances and table writes. A tracked point without a stereo match ends its track:
  // the backend needs stereo observations.
  std::vector<Track> next;
  next.reserve(points.size());
  const size_t num_tracked = tracks.size();
  for (size_t i = 0; i < points.size(); ++i) {
    const bool is_new = i >= num_tracked;
    if (!matches[i].ok()) {
      ++summary.stereo_rejected;
      if (!is_new) {
        ++summary.lost;
        ++summary.lost_in_stereo;
      }
      continue;
    }
    Track t;
    if (is_new) {
      t.pt = detections[i - num_tracked].pt;
      t.level = detections[i - num_tracked].level;
    } else {
      t = tracks[i];
    }
    const Eigen::Vector3d x(t.pt.x, t.pt.y, matches[i].u_right);
    t.disparity = t.pt.x - matches[i].u_right;
    const KeypointCovarianceInput cov_input{t.pt, t.level,
                                            is_new ? 0.0 : static_cast<double>(t.fb_error_px),
                                            matches[i].ncc, matches[i].curvature};
    const Eigen::Matrix3d cov = KeypointCovariance(left_grey, cov_input, options_.covariance);
    const int half = options_.covariance.window_px / 2;
    const bool clipped =
        TouchesLevel(left_grey, t.pt, half, options_.clipped_grey) ||
        TouchesLevel(right_grey, cv::Point2f(matches[i].u_right, t.pt.y), half, options_.clipped_grey);
    if (is_new) {
      ++summary.created;
      if (options_.confirm_new_tracks) {
        t.pending_frame = frame;
        t.pending_x = x;
        t.pending_cov = cov;
        t.pending_clipped = clipped;
      } else {
        t.landmark = table->NewLandmark();
        ++summary.new_landmarks;
        summary.observations += table->Add(t.landmark, frame, x, cov, clipped);
      }
    } else {
      ++summary.tracked;
      if (t.landmark < 0) {
        t.landmark = table->NewLandmark();
        ++summary.new_landmarks;
        summary.observations += table->Add(t.landmark, t.pending_frame, t.pending_x, t.pending_cov,
                                           t.pending_clipped);
      }
      summary.observations += table->Add(t.landmark, frame, x, cov, clipped);
    }
    next.push_back(t);
  }
  if (live_before > 0 && summary.tracked == 0) {
    // Nothing survived: whatever is detected now starts a new, unconnected set of tracks.
    summary.tracking_lost = true;
    GetLogger("frontend")->warn("frame {}: tracking lost ({} live tracks, none continued); "
                                "re-initialising from {} new detections",
                                frame, live_before, summary.created);
  }
  s.tracks = std::move(next);
  s.prev = std::move(cur);
  s.has_prev = true;
  s.last_frame = frame;
  timer.Lap(&summary.covariance_ms, &summary.cpu_covariance_ms);
  total.Lap(&summary.total_ms, &summary.cpu_total_ms);

  GetLogger("frontend")
      ->debug(
          "frame {}: tracked {} created {} lost {} stereo-rejected {} | track {:.1f} ms, detect "
          "{:.1f} ms, stereo {:.1f} ms, cov {:.1f} ms, total {:.1f} ms",
          frame, summary.tracked, summary.created, summary.lost, summary.stereo_rejected,
          summary.track_ms, summary.detect_ms, summary.stereo_ms, summary.covariance_ms,
          summary.total_ms);
  return summary;
}

}  // namespace cslam
