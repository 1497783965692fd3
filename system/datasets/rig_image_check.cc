#include "system/datasets/rig_image_check.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "system/datasets/rig_stereo_source.h"

namespace cslam {

namespace {

VerticalOffsets Summarise(std::vector<double> dy) {
  VerticalOffsets v;
  v.matches = static_cast<int>(dy.size());
  if (dy.empty()) return v;
  std::sort(dy.begin(), dy.end());
  v.median = dy[dy.size() / 2];
  v.p90 = dy[std::min(dy.size() - 1, static_cast<size_t>(0.9 * static_cast<double>(dy.size())))];
  return v;
}

// Corners of the left image followed into the right one by pyramidal Lucas-Kanade (sub-pixel,
// any direction, so a vertical offset is measured rather than assumed away), kept when tracking
// back lands within 0.5 px of the start and the right point is not to the right of the left one.
std::vector<double> OffsetsOf(const cv::Mat& left, const cv::Mat& right) {
  std::vector<cv::Point2f> corners, in_right, back;
  cv::goodFeaturesToTrack(left, corners, 800, 0.01, 8);
  std::vector<double> dy;
  if (corners.empty()) return dy;
  cv::cornerSubPix(left, corners, {4, 4}, {-1, -1},
                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01));
  std::vector<uchar> ok_fwd, ok_bwd;
  std::vector<float> err;
  const cv::Size window(21, 21);
  cv::calcOpticalFlowPyrLK(left, right, corners, in_right, ok_fwd, err, window, 4);
  cv::calcOpticalFlowPyrLK(right, left, in_right, back, ok_bwd, err, window, 4);
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!ok_fwd[i] || !ok_bwd[i] || cv::norm(back[i] - corners[i]) > 0.5) continue;
    if (in_right[i].x > corners[i].x + 1) continue;
    dy.push_back(std::abs(in_right[i].y - corners[i].y));
  }
  return dy;
}

std::string Px(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v << " px";
  return s.str();
}

}  // namespace

VerticalOffsets MeasureVerticalOffsets(const cv::Mat& left, const cv::Mat& right) {
  return Summarise(OffsetsOf(left, right));
}

RigImageCheck CheckRigOnImages(const StereoSource& source, const std::vector<int>& frames) {
  const auto* rig_source = dynamic_cast<const RigStereoSource*>(&source);
  std::vector<double> rect, raw;
  for (int f : frames) {
    const StereoFrame pair = source.Load(f);
    const std::vector<double> r = OffsetsOf(pair.left, pair.right);
    rect.insert(rect.end(), r.begin(), r.end());
    if (rig_source && !rig_source->rectifier().identity()) {
      const StereoFrame recorded = rig_source->LoadRaw(f);
      const std::vector<double> w = OffsetsOf(recorded.left, recorded.right);
      raw.insert(raw.end(), w.begin(), w.end());
    }
  }
  RigImageCheck check;
  check.rectified = Summarise(rect);
  check.raw = Summarise(raw);
  if (check.rectified.matches < 20) {
    check.ok = false;
    check.measured = false;
    check.problem = "only " + std::to_string(check.rectified.matches) +
                    " stereo matches in the checked pairs; expected at least 20 to measure the "
                    "rectification (are both cameras looking at the same textured scene?)";
    return check;
  }
  if (check.rectified.median <= kMaxMedianVerticalOffsetPx) return check;
  check.ok = false;
  check.problem = "matched features lie " + Px(check.rectified.median) +
                  " apart vertically after rectification (median; expected at most " +
                  Px(kMaxMedianVerticalOffsetPx) + ")";
  const bool distorted = rig_source && (rig_source->rig().cam0.HasDistortion() || rig_source->rig().cam1.HasDistortion());
  if (distorted && check.raw.matches >= 20 && check.raw.median < check.rectified.median)
    check.problem += ", but only " + Px(check.raw.median) +
                     " in the images as they are: are these images already rectified? The "
                     "calibration carries distortion coefficients, so they are undistorted twice";
  else
    check.problem += ": does the calibration belong to these cameras, and is cam0 the left one?";
  return check;
}

cv::Mat SideBySideWithLines(const cv::Mat& left, const cv::Mat& right, int line_every) {
  cv::Mat both, colour;
  cv::hconcat(left, right, both);
  cv::cvtColor(both, colour, cv::COLOR_GRAY2BGR);
  for (int y = line_every / 2; y < colour.rows; y += line_every)
    cv::line(colour, {0, y}, {colour.cols - 1, y}, cv::Scalar(0, 200, 0), 1);
  return colour;
}

}  // namespace cslam
