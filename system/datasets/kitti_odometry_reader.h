#pragma once
// KITTI odometry sequence (formats.md, "KITTI odometry").
#include <string>
#include <vector>

#include "system/datasets/stereo_source.h"

namespace cslam {

/// A `sequences/XX` folder: grey pair image_0/image_1, calib.txt (P0, P1; Tr optional),
/// times.txt, and ground truth from ../../poses/XX.txt when that file exists. The constructor
/// validates everything (decoding frame 0 for the image size) and throws InputError naming the
/// file (and line) on any problem.
class KittiOdometrySource : public StereoSource {
 public:
  explicit KittiOdometrySource(const std::string& sequence_dir);

  std::string name() const override { return name_; }
  std::string kind() const override { return "kitti_odometry"; }
  const StereoCamera& camera() const override { return camera_; }
  int size() const override { return static_cast<int>(left_files_.size()); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  StereoFrame Load(int index) const override;
  std::optional<std::vector<Pose>> GroundTruth() const override { return ground_truth_; }

  /// Rectified camera 0 ← velodyne from calib.txt's "Tr:" line, when present.
  const std::optional<Pose>& cam_from_velo() const { return cam_from_velo_; }

 private:
  std::string name_;
  StereoCamera camera_;
  std::optional<Pose> cam_from_velo_;
  std::vector<std::string> left_files_, right_files_;
  std::vector<double> timestamps_;
  std::optional<std::vector<Pose>> ground_truth_;
};

/// Reads a KITTI pose file (12 numbers per line, row-major 3×4 world_from_cam) re-expressed
/// relative to its first line. Throws InputError (file:line) on malformed lines or when the
/// line count is not `expected_lines` (when >= 0).
std::vector<Pose> ReadKittiPoseFile(const std::string& path, int expected_lines = -1);

}  // namespace cslam
