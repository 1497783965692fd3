#include "system/datasets/kitti_odometry_reader.h"

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/kitti_calibration.h"
#include "system/datasets/stereo_pair_files.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

std::vector<Pose> ReadKittiPoseFile(const std::string& path, int expected_lines) {
  std::ifstream in = OpenTextFile(path, "pose file");
  std::vector<Pose> poses;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<double> v = ParseNumbers(line, path, line_no);
    if (v.size() != 12)
      throw InputError(path, line_no,
                       "expected 12 numbers (row-major 3x4 pose), got " + std::to_string(v.size()));
    const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> m(v.data());
    const Eigen::Matrix3d r = m.leftCols<3>();
    if ((r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 ||
        r.determinant() < 0)
      throw InputError(path, line_no, "expected a rotation matrix in the first 3 columns");
    poses.push_back(PoseFrom3x4(m));
  }
  if (poses.empty()) throw InputError(path, "expected one pose per frame; the file is empty");
  if (expected_lines >= 0 && static_cast<int>(poses.size()) != expected_lines)
    throw InputError(path, "expected one pose per frame (" + std::to_string(expected_lines) +
                               "), got " + std::to_string(poses.size()));
  // World = camera at the first line, even when a clip's first line is not the identity.
  const Pose cam0_from_world = poses.front().inverse();
  for (Pose& p : poses) p = cam0_from_world * p;
  return poses;
}

KittiOdometrySource::KittiOdometrySource(const std::string& sequence_dir) {
  const fs::path seq = NormalizedFolder(sequence_dir);
  std::error_code ec;
  if (!fs::is_directory(seq, ec))
    throw InputError(sequence_dir, "expected a KITTI odometry sequence folder; it does not exist");
  name_ = seq.filename().string();

  const KittiOdometryCalib calib = ReadKittiOdometryCalibration((seq / "calib.txt").string());
  camera_ = calib.camera;
  cam_from_velo_ = calib.cam0_from_velo;
  ListStereoPairs((seq / "image_0").string(), (seq / "image_1").string(), &left_files_,
                  &right_files_);
  const fs::path times_file = seq / "times.txt";
  timestamps_ = ReadSecondsTimestamps(times_file.string());
  if (timestamps_.size() != left_files_.size())
    throw InputError(times_file.string(), "expected one timestamp per image (" +
                                              std::to_string(left_files_.size()) + "), got " +
                                              std::to_string(timestamps_.size()));

  // The size comes from the images: calib.txt does not carry it.
  const cv::Mat first = LoadGreyImage(left_files_.front());
  camera_.width = first.cols;
  camera_.height = first.rows;

  const fs::path poses_file = seq.parent_path().parent_path() / "poses" / (name_ + ".txt");
  if (fs::exists(poses_file, ec)) ground_truth_ = ReadKittiPoseFile(poses_file.string(), size());

  Load(0);
  GetLogger("system")->info("KITTI odometry {}: {} frames {}x{}, baseline {:.4f} m, {}", name_,
                            size(), camera_.width, camera_.height, camera_.baseline,
                            ground_truth_ ? "ground truth from " + poses_file.string()
                                          : std::string("no ground truth"));
}

StereoFrame KittiOdometrySource::Load(int index) const {
  return LoadStereoPair(left_files_, right_files_, timestamps_, camera_, index);
}

}  // namespace cslam
