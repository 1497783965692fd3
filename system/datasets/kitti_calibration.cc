#include "system/datasets/kitti_calibration.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <fstream>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

}  // namespace

KeyValueFile KeyValueFile::Read(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "calibration file");
  KeyValueFile file;
  file.path_ = path;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty()) continue;
    const auto colon = t.find(':');
    if (colon == std::string::npos || colon == 0)
      throw InputError(path, line_no, "expected a line 'key: values', got '" + t + "'");
    const std::string key = Trim(t.substr(0, colon));
    if (file.entries_.count(key))
      throw InputError(path, line_no,
                       "key '" + key + "' appears twice (first on line " +
                           std::to_string(file.entries_[key].line) + ")");
    file.entries_[key] = Entry{t.substr(colon + 1), line_no};
  }
  if (in.bad()) throw InputError(path, "read error");
  return file;
}

int KeyValueFile::LineOf(const std::string& key) const {
  const auto it = entries_.find(key);
  return it == entries_.end() ? 0 : it->second.line;
}

std::vector<double> KeyValueFile::Numbers(const std::string& key, int count) const {
  const auto it = entries_.find(key);
  if (it == entries_.end())
    throw InputError(path_, "missing key '" + key + ":' (expected " + std::to_string(count) +
                                " numbers)");
  const std::vector<double> values =
      ParseNumbers(it->second.value, path_, it->second.line, "'" + key + "'");
  if (static_cast<int>(values.size()) != count)
    throw InputError(path_, it->second.line,
                     "'" + key + "': expected " + std::to_string(count) + " numbers, got " +
                         std::to_string(values.size()));
  return values;
}

Eigen::MatrixXd KeyValueFile::Matrix(const std::string& key, int rows, int cols) const {
  const std::vector<double> v = Numbers(key, rows * cols);
  Eigen::MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(r, c) = v[r * cols + c];
  return m;
}

KittiCamToCam ReadKittiCamToCam(const std::string& path) {
  const KeyValueFile file = KeyValueFile::Read(path);
  KittiCamToCam calib;
  calib.path = path;
  calib.r_rect_00 = file.Matrix("R_rect_00", 3, 3);
  for (int cam = 0; cam < 4; ++cam) {
    const std::string suffix = "_0" + std::to_string(cam);
    if (file.Has("P_rect" + suffix)) {
      calib.p_rect[cam] = file.Matrix("P_rect" + suffix, 3, 4);
      calib.p_rect_line[cam] = file.LineOf("P_rect" + suffix);
    }
    if (file.Has("S_rect" + suffix)) {
      const std::vector<double> s = file.Numbers("S_rect" + suffix, 2);
      // The upper bound keeps the int conversion defined (found by fuzz/calibration_fuzzer).
      constexpr double kMaxSide = 1 << 20;
      if (!(s[0] >= 1 && s[1] >= 1 && s[0] <= kMaxSide && s[1] <= kMaxSide) ||
          s[0] != std::floor(s[0]) || s[1] != std::floor(s[1]))
        throw InputError(path, file.LineOf("S_rect" + suffix),
                         "'S_rect" + suffix + "': expected a positive whole image size of at most " +
                             std::to_string(static_cast<int>(kMaxSide)) + " pixels a side");
      calib.s_rect[cam] = Eigen::Vector2i(static_cast<int>(s[0]), static_cast<int>(s[1]));
    }
  }
  return calib;
}

namespace {

// fx, fy, cx, cy from the left projection matrix and the baseline from the right one's
// x-offset; both matrices share the rectified intrinsics.
StereoCamera CameraFromProjections(const Eigen::Matrix<double, 3, 4>& p_left,
                                   const Eigen::Matrix<double, 3, 4>& p_right,
                                   const std::string& path, int left_line, int right_line,
                                   const std::string& left_key, const std::string& right_key) {
  StereoCamera cam;
  cam.fx = p_left(0, 0);
  cam.fy = p_left(1, 1);
  cam.cx = p_left(0, 2);
  cam.cy = p_left(1, 2);
  if (!(cam.fx > 0) || !(cam.fy > 0))
    throw InputError(path, left_line,
                     "'" + left_key + "': expected positive focal lengths P[0,0] and P[1,1]");
  // The x-offsets K⁻¹·P[:,3] of both cameras: equal to P[0,3]/fx when P[1:3,3] = 0 (grey
  // pair, odometry), and right for the colour pair whose P_rect also has y and z terms.
  const Eigen::Matrix3d k = p_left.leftCols<3>();
  if (std::abs(k.determinant()) < 1e-12)
    throw InputError(path, left_line, "'" + left_key + "': expected an invertible 3x3 part");
  const Eigen::Matrix3d k_inv = k.inverse();
  cam.baseline = (k_inv * p_left.col(3)).x() - (k_inv * p_right.col(3)).x();
  if (!(cam.baseline > 0))
    throw InputError(path, right_line,
                     "'" + right_key + "': expected a positive baseline (" + left_key +
                         "[0,3] - " + right_key + "[0,3]) / fx, got " +
                         std::to_string(cam.baseline) + " m");
  return cam;
}

}  // namespace

StereoCamera StereoCameraFromCamToCam(const KittiCamToCam& calib, int left, int right) {
  const std::string lk = "P_rect_0" + std::to_string(left);
  const std::string rk = "P_rect_0" + std::to_string(right);
  if (!calib.p_rect[left]) throw InputError(calib.path, "missing key '" + lk + ":'");
  if (!calib.p_rect[right]) throw InputError(calib.path, "missing key '" + rk + ":'");
  if (!calib.s_rect[left])
    throw InputError(calib.path, "missing key 'S_rect_0" + std::to_string(left) + ":'");
  StereoCamera cam =
      CameraFromProjections(*calib.p_rect[left], *calib.p_rect[right], calib.path,
                            calib.p_rect_line[left], calib.p_rect_line[right], lk, rk);
  cam.width = (*calib.s_rect[left])(0);
  cam.height = (*calib.s_rect[left])(1);
  return cam;
}

Pose CamFromCam0Rect(const KittiCamToCam& calib, int cam) {
  if (!calib.p_rect[cam])
    throw InputError(calib.path, "missing key 'P_rect_0" + std::to_string(cam) + ":'");
  const Eigen::Matrix<double, 3, 4>& p = *calib.p_rect[cam];
  const Eigen::Matrix3d k = p.leftCols<3>();
  if (std::abs(k.determinant()) < 1e-12)
    throw InputError(calib.path, calib.p_rect_line[cam],
                     "'P_rect_0" + std::to_string(cam) + "': expected an invertible 3x3 part");
  Pose pose = Pose::Identity();
  pose.translation() = k.inverse() * p.col(3);
  return pose;
}

Pose PoseFrom3x4(const Eigen::Matrix<double, 3, 4>& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.leftCols<3>(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  Pose pose = Pose::Identity();
  pose.linear() = r;
  pose.translation() = m.col(3);
  return pose;
}

namespace {

// A rotation block is accepted when it is orthonormal to the precision files store (~7 digits).
void CheckRotation(const Eigen::Matrix3d& r, const KeyValueFile& file, const std::string& key) {
  const double err = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (err > 1e-3 || r.determinant() < 0)
    throw InputError(file.path(), file.LineOf(key),
                     "'" + key + "': expected a rotation matrix (orthonormal, det +1)");
}

}  // namespace

Pose ReadKittiRigidCalibration(const std::string& path) {
  const KeyValueFile file = KeyValueFile::Read(path);
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = file.Matrix("R", 3, 3);
  m.col(3) = file.Matrix("T", 3, 1);
  CheckRotation(m.leftCols<3>(), file, "R");
  return PoseFrom3x4(m);
}

KittiOdometryCalib ReadKittiOdometryCalibration(const std::string& path) {
  const KeyValueFile file = KeyValueFile::Read(path);
  KittiOdometryCalib calib;
  calib.p0 = file.Matrix("P0", 3, 4);
  calib.p1 = file.Matrix("P1", 3, 4);
  if (file.Has("Tr")) {
    const Eigen::Matrix<double, 3, 4> tr = file.Matrix("Tr", 3, 4);
    CheckRotation(tr.leftCols<3>(), file, "Tr");
    calib.cam0_from_velo = PoseFrom3x4(tr);
  }
  calib.camera = CameraFromProjections(calib.p0, calib.p1, path, file.LineOf("P0"),
                                       file.LineOf("P1"), "P0", "P1");
  return calib;
}

}  // namespace cslam
