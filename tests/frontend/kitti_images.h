#pragma once
// KITTI grey stereo pairs (raw drive 0005, odometry clip_a) for frontend tests and the
// benchmark, read with
// cv::imread (the project's KITTI readers live in system/, which tests of the frontend layer
// do not need).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "core/stereo_camera.h"

namespace cslam::testing {

/// The shared data folder: $CSLAM_SHARED_DATA when set (lets a build whose compile-time path
/// does not exist, e.g. a git worktree, point at the data), else CSLAM_SHARED_DATA_DIR.
inline std::filesystem::path SharedDataDir() {
  if (const char* env = std::getenv("CSLAM_SHARED_DATA");
      env != nullptr && std::filesystem::is_directory(env))
    return env;
  return CSLAM_SHARED_DATA_DIR;
}

inline std::filesystem::path Drive0005Dir() {
  return SharedDataDir() / "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync";
}

/// Rectified camera of 2011_09_26 from kitti_raw/2011_09_26/calib_cam_to_cam.txt:
/// P_rect_00 = [721.5377 0 609.5593 0; 0 721.5377 172.854 0; 0 0 1 0],
/// P_rect_01[0,3] = -387.5744, so baseline = 387.5744 / 721.5377 = 0.53715 m; S_rect 1242×375.
inline StereoCamera Drive0005Camera() {
  StereoCamera cam;
  cam.fx = cam.fy = 721.5377;
  cam.cx = 609.5593;
  cam.cy = 172.854;
  cam.baseline = 387.5744 / 721.5377;
  cam.width = 1242;
  cam.height = 375;
  return cam;
}

/// A left and a right grey image; empty when missing.
struct StereoPair {
  cv::Mat left, right;
};

/// Left (image_00) and right (image_01) of drive 0005 frame `index`.
inline StereoPair LoadDrive0005Pair(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%010d.png", index);
  StereoPair pair;
  pair.left = cv::imread((Drive0005Dir() / "image_00/data" / name).string(), cv::IMREAD_GRAYSCALE);
  pair.right = cv::imread((Drive0005Dir() / "image_01/data" / name).string(), cv::IMREAD_GRAYSCALE);
  return pair;
}

/// The odometry clip_a camera from sequences/clip_a/calib.txt: P0 = [707.0912 0 601.8873 0;
/// 0 707.0912 183.1104 0; 0 0 1 0], P1[0,3] = -379.8145 → baseline 379.8145 / 707.0912 =
/// 0.53715 m; images 1226×370.
inline StereoCamera ClipACamera() {
  StereoCamera cam;
  cam.fx = cam.fy = 707.0912;
  cam.cx = 601.8873;
  cam.cy = 183.1104;
  cam.baseline = 379.8145 / 707.0912;
  cam.width = 1226;
  cam.height = 370;
  return cam;
}

/// Left (image_0) and right (image_1) of odometry clip_a frame `index`.
inline StereoPair LoadClipAPair(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  const std::filesystem::path dir = SharedDataDir() / "kitti_odometry/sequences/clip_a";
  StereoPair pair;
  pair.left = cv::imread((dir / "image_0" / name).string(), cv::IMREAD_GRAYSCALE);
  pair.right = cv::imread((dir / "image_1" / name).string(), cv::IMREAD_GRAYSCALE);
  return pair;
}

}  // namespace cslam::testing
