#pragma once
// KITTI raw synced + rectified drive (formats.md, "KITTI raw").
#include <string>
#include <vector>

#include "system/datasets/stereo_source.h"

namespace cslam {

/// A `<date>_drive_NNNN_sync` folder: grey pair image_00/01 or colour pair image_02/03
/// (decoded to grey), ground truth from oxts/, labelled boxes from tracklet_labels.xml.
/// The calibration files are looked up in the drive's parent folder, then the drive folder.
/// The constructor reads and validates everything except the images (it decodes frame 0
/// only) and throws InputError naming the file (and line) on any problem.
class KittiRawSource : public StereoSource {
 public:
  KittiRawSource(const std::string& drive_dir, bool color = false);

  std::string name() const override { return name_; }
  std::string kind() const override { return "kitti_raw"; }
  const StereoCamera& camera() const override { return camera_; }
  int size() const override { return static_cast<int>(left_files_.size()); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  StereoFrame Load(int index) const override;
  std::optional<std::vector<Pose>> GroundTruth() const override { return ground_truth_; }
  std::vector<std::vector<ObjectBox>> ObjectBoxes() const override { return boxes_; }
  /// The OXTS's dead-reckoned path (its velocities integrated) and its stated position accuracy.
  std::optional<GroundTruthCrossCheck> CrossCheck() const override { return cross_check_; }

  /// Rectified left camera ← velodyne (includes R_rect_00 and, for colour, camera 02's offset).
  const Pose& cam_from_velo() const { return cam_from_velo_; }
  /// Rectified left camera ← IMU/OXTS.
  const Pose& cam_from_imu() const { return cam_from_imu_; }

 private:
  std::string name_;
  StereoCamera camera_;
  std::vector<std::string> left_files_, right_files_;
  std::vector<double> timestamps_;
  Pose cam_from_velo_ = Pose::Identity();
  Pose cam_from_imu_ = Pose::Identity();
  std::optional<std::vector<Pose>> ground_truth_;
  std::optional<GroundTruthCrossCheck> cross_check_;
  std::vector<std::vector<ObjectBox>> boxes_;
};

}  // namespace cslam
