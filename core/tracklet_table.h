#pragma once
// The seam between frontend (or synthetic generator) and backend: a sparse landmark × frame
// table of stereo observations with per-observation pixel covariance.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace cslam {

/// One stereo keypoint of a landmark in a frame: x = (uL, vL, uR) px, cov 3×3 px².
struct StereoObservation {
  int landmark = -1;
  int frame = -1;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  /// The keypoint's patch (left or right) holds clipped, saturated pixels: its position error
  /// follows the exposure of each image, not the covariance model, so it is no evidence of
  /// motion (backend/moving_test.h).
  bool clipped = false;
};

/// Half-open frame interval [begin, end).
struct FrameRange {
  int begin = 0;
  int end = 0;
  int size() const { return end - begin; }
  bool Contains(int frame) const { return frame >= begin && frame < end; }
  bool operator==(const FrameRange&) const = default;
};

/// Chunks of `length` frames overlapping by `overlap` (stride length - overlap) covering
/// [0, num_frames); the last chunk is cut at num_frames, and a last chunk shorter than
/// the overlap (already covered) is not emitted. Precondition: 0 <= overlap < length.
std::vector<FrameRange> SplitIntoChunks(int num_frames, int length, int overlap);

/// A landmark's whole track, kept when its observations are forgotten: the first and last
/// frame it was observed in and how many observations it had.
struct LandmarkSpan {
  int first_frame = -1;
  int last_frame = -1;
  int observations = 0;
};

/// Reference to an observation stored in the table.
struct ObservationRef {
  int landmark = -1;
  int index = -1;  ///< position in ObservationsOf(landmark)
};

/// Sparse landmark × frame observation store. Landmark ids are dense (0..num_landmarks-1);
/// each landmark's observations are kept sorted by frame, so windows are views, not copies.
/// Iteration order is deterministic (by id, then by frame). Not thread-safe: the online
/// system guards it.
class TrackletTable {
 public:
  /// Adds an observation; creates landmark ids up to `landmark` as needed. Returns false (and
  /// changes nothing) when the landmark already has an observation in that frame.
  bool Add(int landmark, int frame, const Eigen::Vector3d& x, const Eigen::Matrix3d& cov,
           bool clipped = false);
  /// A fresh landmark id (= num_landmarks() before the call).
  int NewLandmark();

  int num_landmarks() const { return static_cast<int>(by_landmark_.size()); }
  /// One past the largest frame index seen.
  int num_frames() const { return static_cast<int>(by_frame_.size()); }
  /// Observations held now (forgotten ones are not counted).
  size_t num_observations() const { return num_observations_; }

  /// All observations of a landmark, sorted by frame.
  std::span<const StereoObservation> ObservationsOf(int landmark) const;
  /// The observations of a landmark inside `range`, sorted by frame.
  std::span<const StereoObservation> ObservationsOf(int landmark, FrameRange range) const;
  /// Observations in a frame, sorted by landmark id.
  const std::vector<ObservationRef>& ObservationsAt(int frame) const;
  const StereoObservation& Get(ObservationRef ref) const {
    return by_landmark_[ref.landmark][ref.index];
  }
  /// Landmarks with at least `min_observations` observations inside `range`, ascending ids.
  std::vector<int> LandmarksIn(FrameRange range, int min_observations = 1) const;
  /// Frames (ascending) in `range` where both landmarks are observed.
  std::vector<int> CoObservedFrames(int a, int b, FrameRange range) const;
  std::vector<int> CoObservedFrames(int a, int b) const {
    return CoObservedFrames(a, b, {0, num_frames()});
  }
  /// A copy holding only the observations inside `range` (same landmark ids), for handing a
  /// window to another thread.
  TrackletTable Slice(FrameRange range) const;
  /// The same observations with the landmarks renumbered 0..m−1 in ascending id order;
  /// `ids` receives each new id's id here. A window's table then costs what the window holds,
  /// not every landmark the run has made.
  TrackletTable CompactSlice(FrameRange range, std::vector<int>* ids) const;

  /// Releases the observations of every frame before `frame` (a long online run keeps only
  /// what later windows need); spans, landmark ids and frame numbering are kept. Frames
  /// before `frame` then have no observations. Adding to a forgotten frame is an error.
  void ForgetBefore(int frame);
  /// First frame whose observations are still held (0 unless ForgetBefore was called).
  int first_held_frame() const { return first_held_frame_; }
  /// The landmark's whole track, including forgotten observations.
  const LandmarkSpan& Span(int landmark) const;

 private:
  std::vector<std::vector<StereoObservation>> by_landmark_;
  std::vector<std::vector<ObservationRef>> by_frame_;
  std::vector<LandmarkSpan> spans_;
  size_t num_observations_ = 0;
  int first_held_frame_ = 0;
};

}  // namespace cslam
