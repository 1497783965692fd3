#include "system/datasets/kitti_raw_reader.h"

#include <filesystem>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/kitti_calibration.h"
#include "system/datasets/kitti_tracklets.h"
#include "system/datasets/oxts.h"
#include "system/datasets/stereo_pair_files.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// The date folder holds the calibration in the official layout; some copies keep it beside
// the images instead.
fs::path FindCalibration(const fs::path& drive, const std::string& file) {
  for (const fs::path& dir : {drive.parent_path(), drive}) {
    std::error_code ec;
    if (fs::exists(dir / file, ec)) return dir / file;
  }
  throw InputError((drive / file).string(),
                   "expected the calibration file " + file +
                       " in the drive's parent folder or the drive folder; it is missing");
}

}  // namespace

KittiRawSource::KittiRawSource(const std::string& drive_dir, bool color) {
  const fs::path drive = NormalizedFolder(drive_dir);
  std::error_code ec;
  if (!fs::is_directory(drive, ec))
    throw InputError(drive_dir, "expected a KITTI raw drive folder; it does not exist");
  name_ = drive.filename().string();

  const int left = color ? 2 : 0;
  const int right = left + 1;
  const std::string left_name = "image_0" + std::to_string(left);
  const std::string right_name = "image_0" + std::to_string(right);

  const KittiCamToCam calib = ReadKittiCamToCam(FindCalibration(drive, "calib_cam_to_cam.txt").string());
  camera_ = StereoCameraFromCamToCam(calib, left, right);

  ListStereoPairs((drive / left_name / "data").string(), (drive / right_name / "data").string(),
                  &left_files_, &right_files_);
  const fs::path times_file = drive / left_name / "timestamps.txt";
  timestamps_ = ReadKittiRawTimestamps(times_file.string());
  if (timestamps_.size() != left_files_.size())
    throw InputError(times_file.string(), "expected one timestamp per image (" +
                                              std::to_string(left_files_.size()) + "), got " +
                                              std::to_string(timestamps_.size()));

  // Frame chain (formats.md): rectified left ← rectified cam0 ← cam0 ← velodyne ← IMU.
  Pose cam0rect_from_cam0 = Pose::Identity();
  Eigen::Matrix<double, 3, 4> r_rect = Eigen::Matrix<double, 3, 4>::Zero();
  r_rect.leftCols<3>() = calib.r_rect_00;
  cam0rect_from_cam0 = PoseFrom3x4(r_rect);
  const Pose cam_from_cam0 = CamFromCam0Rect(calib, left) * cam0rect_from_cam0;

  const bool has_oxts = fs::exists(drive / "oxts", ec);
  const bool has_labels = fs::exists(drive / "tracklet_labels.xml", ec);
  if (has_oxts || has_labels) {
    const Pose cam0_from_velo =
        ReadKittiRigidCalibration(FindCalibration(drive, "calib_velo_to_cam.txt").string());
    cam_from_velo_ = cam_from_cam0 * cam0_from_velo;
  }
  if (has_oxts) {
    const Pose velo_from_imu =
        ReadKittiRigidCalibration(FindCalibration(drive, "calib_imu_to_velo.txt").string());
    cam_from_imu_ = cam_from_velo_ * velo_from_imu;
    const std::vector<OxtsPacket> packets = ReadOxts((drive / "oxts").string());
    if (packets.size() != left_files_.size())
      throw InputError((drive / "oxts" / "data").string(),
                       "expected one OXTS packet per image (" + std::to_string(left_files_.size()) +
                           "), got " + std::to_string(packets.size()));
    ground_truth_ = OxtsToCameraPoses(packets, cam_from_imu_);
    GroundTruthCrossCheck check;
    check.source = "OXTS velocities integrated";
    // The packets are synchronised to the images (one per frame), so the image clock times them.
    check.positions = OxtsDeadReckonedCameraPositions(packets, timestamps_, cam_from_imu_);
    for (const OxtsPacket& p : packets) check.position_accuracy_m.push_back(p.pos_accuracy);
    cross_check_ = std::move(check);
  }
  if (has_labels)
    boxes_ = ReadTrackletLabels((drive / "tracklet_labels.xml").string(), cam_from_velo_, size());

  Load(0);  // fail here, not mid-run, when the images do not match the calibration
  GetLogger("system")->info("KITTI raw {}: {} frames {}x{}, baseline {:.4f} m, {}{}", name_, size(),
                            camera_.width, camera_.height, camera_.baseline,
                            ground_truth_ ? "OXTS ground truth" : "no ground truth",
                            has_labels ? ", tracklet labels" : "");
}

StereoFrame KittiRawSource::Load(int index) const {
  return LoadStereoPair(left_files_, right_files_, timestamps_, camera_, index);
}

}  // namespace cslam
