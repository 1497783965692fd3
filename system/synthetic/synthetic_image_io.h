#pragma once
// Rendered stereo images of a synthetic sequence, on disk in the KITTI odometry layout so the
// KITTI odometry reader opens them unchanged (docs/formats.md, "Synthetic sequence with
// images"), next to the synthetic ground-truth files of WriteSynthetic:
//
//   DIR/sequences/00/image_0/NNNNNN.png    left grey images
//   DIR/sequences/00/image_1/NNNNNN.png    right grey images
//   DIR/sequences/00/object_id/NNNNNN.png  16-bit object id under each left pixel (65535: none)
//   DIR/sequences/00/calib.txt             P0, P1 (KITTI)
//   DIR/sequences/00/times.txt             seconds per frame
//   DIR/poses/00.txt                       world_from_cam per frame (KITTI)
#include <opencv2/core/mat.hpp>
#include <string>

#include "system/synthetic/synthetic_scene.h"

namespace cslam {

/// DIR/sequences/00: the KITTI odometry sequence folder of a synthetic sequence folder.
std::string SyntheticImagesDir(const std::string& dir);

/// True when `dir` holds rendered images (sequences/00 with image_0/ and calib.txt; names only).
bool HasSyntheticImages(const std::string& dir);

/// DIR/poses/00.txt: the camera poses beside the images.
std::string SyntheticPosesFile(const std::string& dir);

/// The file name of frame `frame` in image_0/, image_1/ and object_id/ ("000042.png").
std::string SyntheticFrameFile(int frame);

/// The object-id image (CV_16UC1) of frame `frame` written by WriteSyntheticImages. Throws
/// InputError naming the file when it is missing or not a 16-bit single-channel PNG.
cv::Mat ReadObjectIdImage(const std::string& dir, int frame);

}  // namespace cslam
