#include "core/tracklet_table.h"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include "core/errors.h"

namespace cslam {

std::vector<FrameRange> SplitIntoChunks(int num_frames, int length, int overlap) {
  CSLAM_CHECK(length > 0 && overlap >= 0 && overlap < length, "bad chunk length/overlap");
  std::vector<FrameRange> chunks;
  if (num_frames <= 0) return chunks;
  const int stride = length - overlap;
  for (int begin = 0;; begin += stride) {
    const int end = std::min(begin + length, num_frames);
    chunks.push_back({begin, end});
    if (end >= num_frames) break;
  }
  // A short tail chunk carries almost no co-observations: merge it into the previous one.
  if (chunks.size() >= 2 && chunks.back().size() < length / 2) {
    chunks.pop_back();
    chunks.back().end = num_frames;
  }
  return chunks;
}

int TrackletTable::NewLandmark() {
  by_landmark_.emplace_back();
  spans_.emplace_back();
  return num_landmarks() - 1;
}

bool TrackletTable::Add(int landmark, int frame, const Eigen::Vector3d& x,
                        const Eigen::Matrix3d& cov, bool clipped) {
  CSLAM_CHECK(landmark >= 0 && frame >= 0, "negative landmark or frame id");
  CSLAM_CHECK(frame >= first_held_frame_, "observation added to a forgotten frame");
  if (landmark >= num_landmarks()) {
    by_landmark_.resize(landmark + 1);
    spans_.resize(landmark + 1);
  }
  if (frame >= num_frames()) by_frame_.resize(frame + 1);
  auto& obs = by_landmark_[landmark];
  auto it = std::lower_bound(obs.begin(), obs.end(), frame,
                             [](const StereoObservation& o, int f) { return o.frame < f; });
  if (it != obs.end() && it->frame == frame) return false;
  const bool append = it == obs.end();
  obs.insert(it, StereoObservation{landmark, frame, x, cov, clipped});
  if (!append) {
    // Indices of later observations of this landmark shifted: fix their frame refs.
    for (size_t i = 0; i < obs.size(); ++i) {
      for (auto& ref : by_frame_[obs[i].frame])
        if (ref.landmark == landmark) ref.index = static_cast<int>(i);
    }
  }
  auto& refs = by_frame_[frame];
  const ObservationRef ref{landmark, static_cast<int>(
      std::find_if(obs.begin(), obs.end(), [&](const auto& o) { return o.frame == frame; }) -
      obs.begin())};
  auto pos = std::lower_bound(refs.begin(), refs.end(), landmark,
                              [](const ObservationRef& r, int l) { return r.landmark < l; });
  refs.insert(pos, ref);
  ++num_observations_;
  LandmarkSpan& span = spans_[landmark];
  span.first_frame = span.observations == 0 ? frame : std::min(span.first_frame, frame);
  span.last_frame = std::max(span.last_frame, frame);
  ++span.observations;
  return true;
}

const LandmarkSpan& TrackletTable::Span(int landmark) const {
  CSLAM_CHECK(landmark >= 0 && landmark < num_landmarks(), "landmark id out of range");
  return spans_[landmark];
}

void TrackletTable::ForgetBefore(int frame) {
  frame = std::min(frame, num_frames());
  if (frame <= first_held_frame_) return;
  // Observations are sorted by frame per landmark, so each landmark loses a prefix; the
  // frame refs of the frames kept index into those vectors and shift by the same amount.
  std::unordered_map<int, int> dropped;
  for (int f = first_held_frame_; f < frame; ++f) {
    for (const ObservationRef& ref : by_frame_[f]) ++dropped[ref.landmark];
    num_observations_ -= by_frame_[f].size();
    std::vector<ObservationRef>().swap(by_frame_[f]);
  }
  for (const auto& [landmark, n] : dropped) {
    auto& obs = by_landmark_[landmark];
    obs.erase(obs.begin(), obs.begin() + n);
    // A finished track frees its memory; a live one only when it holds far more than it uses.
    // (Short tracks, the most common, never reach the slack: free an emptied one outright.)
    if (obs.empty())
      std::vector<StereoObservation>().swap(obs);
    else if (obs.capacity() > 2 * obs.size() + 8)
      obs.shrink_to_fit();
  }
  for (int f = frame; f < num_frames(); ++f)
    for (ObservationRef& ref : by_frame_[f]) {
      const auto it = dropped.find(ref.landmark);
      if (it != dropped.end()) ref.index -= it->second;
    }
  first_held_frame_ = frame;
}

std::span<const StereoObservation> TrackletTable::ObservationsOf(int landmark) const {
  CSLAM_CHECK(landmark >= 0 && landmark < num_landmarks(), "landmark id out of range");
  return by_landmark_[landmark];
}

std::span<const StereoObservation> TrackletTable::ObservationsOf(int landmark,
                                                                 FrameRange range) const {
  const auto all = ObservationsOf(landmark);
  auto lo = std::lower_bound(all.begin(), all.end(), range.begin,
                             [](const StereoObservation& o, int f) { return o.frame < f; });
  auto hi = std::lower_bound(lo, all.end(), range.end,
                             [](const StereoObservation& o, int f) { return o.frame < f; });
  return all.subspan(lo - all.begin(), hi - lo);
}

const std::vector<ObservationRef>& TrackletTable::ObservationsAt(int frame) const {
  static const std::vector<ObservationRef> kEmpty;
  if (frame < 0 || frame >= num_frames()) return kEmpty;
  return by_frame_[frame];
}

std::vector<int> TrackletTable::LandmarksIn(FrameRange range, int min_observations) const {
  std::vector<int> out;
  const int begin = std::max(range.begin, 0), end = std::min(range.end, num_frames());
  if (begin >= end) return out;
  // Count per landmark through the per-frame index: cost is the window's size, not the table's.
  // Ids are handed out in order, so a window's span few more ids than it has landmarks: a
  // count per id of that span replaces sorting every observation (called several times per
  // online window).
  int lo = std::numeric_limits<int>::max(), hi = -1;
  for (int f = begin; f < end; ++f)
    for (const auto& ref : by_frame_[f]) {
      lo = std::min(lo, ref.landmark);
      hi = std::max(hi, ref.landmark);
    }
  if (hi < lo) return out;
  std::vector<int> count(static_cast<size_t>(hi - lo) + 1, 0);
  for (int f = begin; f < end; ++f)
    for (const auto& ref : by_frame_[f]) ++count[ref.landmark - lo];
  for (int i = 0; i <= hi - lo; ++i)
    if (count[i] > 0 && count[i] >= min_observations) out.push_back(lo + i);
  return out;
}

std::vector<int> TrackletTable::CoObservedFrames(int a, int b, FrameRange range) const {
  const auto oa = ObservationsOf(a, range), ob = ObservationsOf(b, range);
  std::vector<int> out;
  size_t i = 0, j = 0;
  while (i < oa.size() && j < ob.size()) {
    if (oa[i].frame < ob[j].frame) {
      ++i;
    } else if (ob[j].frame < oa[i].frame) {
      ++j;
    } else {
      out.push_back(oa[i].frame);
      ++i;
      ++j;
    }
  }
  return out;
}

TrackletTable TrackletTable::Slice(FrameRange range) const {
  TrackletTable out;
  out.by_landmark_.resize(by_landmark_.size());
  out.spans_.resize(spans_.size());
  for (int l : LandmarksIn(range)) {
    for (const auto& o : ObservationsOf(l, range)) out.Add(l, o.frame, o.x, o.cov, o.clipped);
  }
  return out;
}

TrackletTable TrackletTable::CompactSlice(FrameRange range, std::vector<int>* ids) const {
  *ids = LandmarksIn(range);
  TrackletTable out;
  out.by_landmark_.resize(ids->size());
  out.spans_.resize(ids->size());
  for (int local = 0; local < static_cast<int>(ids->size()); ++local)
    for (const auto& o : ObservationsOf((*ids)[local], range)) out.Add(local, o.frame, o.x, o.cov, o.clipped);
  return out;
}

}  // namespace cslam
