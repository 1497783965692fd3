#pragma once
// Ground truth for a frontend's landmarks on a rendered synthetic sequence. The frontend's
// landmark ids have nothing to do with the generator's, so each landmark is labelled by what
// was rendered under its first left keypoint: the object id image at that pixel gives its
// body, and the left camera's ray through the pixel, cast against that body's surfaces at that
// frame, gives the surface point it started on (in the body's frame) — the same two facts
// SyntheticSequence::landmark_object / landmark_in_object hold for generated landmarks.
#include <Eigen/Core>
#include <functional>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "core/tracklet_table.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {

/// Per landmark id of a table: its true body (-1 when its first keypoint is outside the image
/// or on no surface) and its point in that body's frame (valid when object >= 0).
struct LandmarkTruth {
  std::vector<int> object;
  std::vector<Eigen::Vector3d> in_object;
};

/// Labels every landmark of `table` (see the file comment). `object_ids(frame)` returns that
/// frame's CV_16UC1 id image (ReadObjectIdImage); it is called once per frame that starts a
/// landmark. When the ray misses the labelled body (a keypoint on a silhouette's last pixel),
/// the point is the keypoint's stereo back-projection mapped into the body's frame.
LandmarkTruth LabelLandmarksByIdImages(const TrackletTable& table, const SyntheticSequence& sequence,
                                       const std::function<cv::Mat(int)>& object_ids);

}  // namespace cslam
