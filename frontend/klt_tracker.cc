#include "frontend/klt_tracker.h"

#include <cmath>
#include <opencv2/video/tracking.hpp>

#include "core/options_reader.h"
#include "frontend/image_patch.h"

namespace cslam {

void KltTrackerOptions::Check() const {
  CheckOption(window_px >= 5 && window_px % 2 == 1, "window_px", "must be odd and >= 5 px",
              window_px);
  CheckOption(max_level >= 0 && max_level <= 8, "max_level", "must be in [0, 8]", max_level);
  CheckOption(max_iterations > 0, "max_iterations", "must be > 0", max_iterations);
  CheckOption(epsilon_px > 0, "epsilon_px", "must be > 0 px", epsilon_px);
  CheckOption(max_fb_error_px > 0, "max_fb_error_px", "must be > 0 px", max_fb_error_px);
  CheckOption(ncc_patch_px >= 3 && ncc_patch_px % 2 == 1, "ncc_patch_px", "must be odd and >= 3 px",
              ncc_patch_px);
  CheckOption(min_ncc >= -1 && min_ncc <= 1, "min_ncc", "must be in [-1, 1]", min_ncc);
  CheckOption(border_px >= 0, "border_px", "must be >= 0 px", border_px);
}

void KltTrackerOptions::Load(OptionsReader& reader) {
  reader.Read("window_px", &window_px);
  reader.Read("max_level", &max_level);
  reader.Read("max_iterations", &max_iterations);
  reader.Read("epsilon_px", &epsilon_px);
  reader.Read("max_fb_error_px", &max_fb_error_px);
  reader.Read("ncc_patch_px", &ncc_patch_px);
  reader.Read("min_ncc", &min_ncc);
  reader.Read("border_px", &border_px);
}

KltTracker::KltTracker(const KltTrackerOptions& options) : options_(options) { options_.Check(); }

KltPyramid KltTracker::BuildPyramid(const cv::Mat& grey) const {
  KltPyramid pyr;
  cv::buildOpticalFlowPyramid(grey, pyr.levels, cv::Size(options_.window_px, options_.window_px),
                              options_.max_level, /*withDerivatives=*/true);
  // Level 0 is a bordered copy (the border mode is not BORDER_TRANSPARENT), so the pyramid
  // does not alias the caller's buffer, which a reader may reuse for the next frame.
  pyr.image = pyr.levels[0];
  return pyr;
}

std::vector<TrackResult> KltTracker::Track(const KltPyramid& prev, const KltPyramid& cur,
                                           std::span<const cv::Point2f> prev_points,
                                           std::span<const cv::Point2f> predicted) const {
  const size_t n = prev_points.size();
  std::vector<TrackResult> out(n);
  if (n == 0) return out;
  const cv::Size win(options_.window_px, options_.window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                              options_.max_iterations, options_.epsilon_px);
  std::vector<cv::Point2f> p0(prev_points.begin(), prev_points.end());
  std::vector<cv::Point2f> p1 =
      predicted.size() == n ? std::vector<cv::Point2f>(predicted.begin(), predicted.end()) : p0;
  std::vector<uchar> status_fwd, status_bwd;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(prev.levels, cur.levels, p0, p1, status_fwd, err, win,
                           options_.max_level, term, cv::OPTFLOW_USE_INITIAL_FLOW);
  // Backward from the forward result, seeded with the same motion guess reversed (not with
  // the start point, which would hand the check its answer): a correct track returns.
  std::vector<cv::Point2f> back(n);
  for (size_t i = 0; i < n; ++i)
    back[i] = p1[i] - (predicted.size() == n ? predicted[i] - p0[i] : cv::Point2f(0, 0));
  cv::calcOpticalFlowPyrLK(cur.levels, prev.levels, p1, back, status_bwd, err, win,
                           options_.max_level, term, cv::OPTFLOW_USE_INITIAL_FLOW);

  const float b = static_cast<float>(options_.border_px);
  const float w = static_cast<float>(cur.image.cols), h = static_cast<float>(cur.image.rows);
  ImagePatch a, c;
  for (size_t i = 0; i < n; ++i) {
    TrackResult& r = out[i];
    r.pt = p1[i];
    if (!status_fwd[i] || !status_bwd[i]) {
      r.status = TrackReject::kLost;
      continue;
    }
    if (!(r.pt.x >= b && r.pt.y >= b && r.pt.x <= w - 1 - b && r.pt.y <= h - 1 - b)) {
      r.status = TrackReject::kOutOfImage;
      continue;
    }
    r.fb_error_px = static_cast<float>(std::hypot(back[i].x - p0[i].x, back[i].y - p0[i].y));
    if (!(r.fb_error_px <= options_.max_fb_error_px)) {
      r.status = TrackReject::kForwardBackward;
      continue;
    }
    if (options_.min_ncc > -1) {
      const int s = options_.ncc_patch_px;
      if (!SamplePatch(prev.image, p0[i].x, p0[i].y, s, &a) ||
          !SamplePatch(cur.image, r.pt.x, r.pt.y, s, &c)) {
        r.status = TrackReject::kOutOfImage;
        continue;
      }
      r.ncc = static_cast<float>(Ncc(a, c));
      if (r.ncc < options_.min_ncc) {
        r.status = TrackReject::kPhotometric;
        continue;
      }
    }
    r.status = TrackReject::kOk;
  }
  return out;
}

}  // namespace cslam
