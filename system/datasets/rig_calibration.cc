#include "system/datasets/rig_calibration.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/errors.h"
#include "system/datasets/calibration_yaml.h"

namespace cslam {

namespace {

// Files keep ~9 digits: project onto SO(3) so the rig's rotation is exact.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& r) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

StereoRig NewRig(const std::string& source, const std::string& format) {
  StereoRig rig;
  rig.source = source;
  rig.format = format;
  return rig;
}

Pose PoseFromMatrix(const CalibrationYaml& y, const YAML::Node& parent, const std::string& key) {
  const Eigen::Matrix4d m = y.Matrix(parent, key, 4, 4);
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 || r.determinant() < 0)
    y.Fail(parent[key], key, "expected a rotation matrix in the upper-left 3x3 block");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9)
    y.Fail(parent[key], key, "expected 0 0 0 1 as the last row of a 4x4 transform");
  Pose p = Pose::Identity();
  p.linear() = NearestRotation(r);
  p.translation() = m.block<3, 1>(0, 3);
  return p;
}

LensModel ParseLens(const CalibrationYaml& y, const YAML::Node& parent, const std::string& key) {
  const std::string w = y.Text(parent, key);
  if (w == "radtan" || w == "radial-tangential" || w == "plumb_bob" || w == "PinHole")
    return LensModel::kRadialTangential;
  if (w == "equidistant" || w == "fisheye" || w == "equi" || w == "KannalaBrandt8")
    return LensModel::kEquidistant;
  if (w == "none") return LensModel::kNone;
  y.Fail(parent[key], key, "unknown distortion model '" + w +
                               "'; expected radtan (radial-tangential), equidistant (fisheye) or none");
}

// A side of the image in pixels, checked before the conversion (a double beyond int's range
// converted to int is undefined behaviour).
int ImageSide(const CalibrationYaml& y, const YAML::Node& node, const std::string& key, double v) {
  if (!(v >= 1 && v <= 20000) || v != static_cast<double>(static_cast<long>(v)))
    y.Fail(node, key, "expected a whole number of pixels in 1-20000, got " + std::to_string(v));
  return static_cast<int>(v);
}

int ImageSide(const CalibrationYaml& y, const YAML::Node& parent, const std::string& key) {
  return ImageSide(y, parent[key], key, y.Number(parent, key));
}

void ReadSize(const CalibrationYaml& y, const YAML::Node& parent, const std::string& key,
              CameraIntrinsics* cam) {
  const std::vector<double> r = y.Numbers(parent, key, 2);
  cam->width = ImageSide(y, parent[key], key, r[0]);
  cam->height = ImageSide(y, parent[key], key, r[1]);
}

void ReadPinhole(const CalibrationYaml& y, const YAML::Node& parent, CameraIntrinsics* cam) {
  if (CalibrationYaml::Has(parent, "camera_model") && y.Text(parent, "camera_model") != "pinhole")
    y.Fail(parent["camera_model"], "camera_model",
           "expected pinhole, got '" + y.Text(parent, "camera_model") +
               "' (other projection models are not supported)");
  const std::vector<double> k = y.Numbers(parent, "intrinsics", 4);
  cam->fx = k[0];
  cam->fy = k[1];
  cam->cx = k[2];
  cam->cy = k[3];
  ReadSize(y, parent, "resolution", cam);
}

CameraIntrinsics ReadEurocCamera(const CalibrationYaml& y, Pose* body_from_cam) {
  CameraIntrinsics cam;
  ReadPinhole(y, y.root(), &cam);
  cam.lens = ParseLens(y, y.root(), "distortion_model");
  cam.distortion = y.Numbers(y.root(), "distortion_coefficients");
  *body_from_cam = PoseFromMatrix(y, y.root(), "T_BS");
  return cam;
}

CameraIntrinsics ReadKalibrCamera(const CalibrationYaml& y, const YAML::Node& node) {
  CameraIntrinsics cam;
  ReadPinhole(y, node, &cam);
  cam.lens = ParseLens(y, node, "distortion_model");
  cam.distortion = y.Numbers(node, "distortion_coeffs");
  return cam;
}

}  // namespace

StereoRig ReadEurocSensorPair(const std::string& cam0_yaml, const std::string& cam1_yaml) {
  const CalibrationYaml y0 = CalibrationYaml::Read(cam0_yaml), y1 = CalibrationYaml::Read(cam1_yaml);
  StereoRig rig = NewRig(cam0_yaml + " and " + cam1_yaml, "euroc");
  Pose body_from_cam0, body_from_cam1;
  rig.cam0 = ReadEurocCamera(y0, &body_from_cam0);
  rig.cam1 = ReadEurocCamera(y1, &body_from_cam1);
  rig.cam1_from_cam0 = body_from_cam1.inverse() * body_from_cam0;
  rig.body_from_cam0 = body_from_cam0;
  return rig;
}

StereoRig ReadKalibrCamchain(const std::string& path) {
  const CalibrationYaml y = CalibrationYaml::Read(path);
  StereoRig rig = NewRig(path, "kalibr");
  const YAML::Node c0 = y.Map(y.root(), "cam0"), c1 = y.Map(y.root(), "cam1");
  rig.cam0 = ReadKalibrCamera(y, c0);
  rig.cam1 = ReadKalibrCamera(y, c1);
  rig.cam1_from_cam0 = PoseFromMatrix(y, c1, "T_cn_cnm1");
  if (CalibrationYaml::Has(c0, "T_cam_imu")) rig.body_from_cam0 = PoseFromMatrix(y, c0, "T_cam_imu").inverse();
  return rig;
}

StereoRig ReadOpenCvStereoCalibration(const std::string& path) {
  const CalibrationYaml y = CalibrationYaml::Read(path);
  const YAML::Node& r = y.root();
  StereoRig rig = NewRig(path, "opencv");
  LensModel lens = LensModel::kRadialTangential;
  if (CalibrationYaml::Has(r, "distortion_model")) lens = ParseLens(y, r, "distortion_model");
  const int width = ImageSide(y, r, "image_width");
  const int height = ImageSide(y, r, "image_height");
  const auto camera = [&](const std::string& m, const std::string& d) {
    const Eigen::Matrix3d k = y.Matrix(r, m, 3, 3);
    if (k(0, 1) != 0.0 || k(1, 0) != 0.0 || k(2, 0) != 0.0 || k(2, 1) != 0.0 || k(2, 2) != 1.0)
      y.Fail(r[m], m, "expected a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]");
    CameraIntrinsics cam;
    cam.fx = k(0, 0);
    cam.fy = k(1, 1);
    cam.cx = k(0, 2);
    cam.cy = k(1, 2);
    cam.width = width;
    cam.height = height;
    cam.lens = lens;
    cam.distortion = y.Numbers(r, d);
    if (lens == LensModel::kRadialTangential && cam.distortion.size() > 5) {
      bool extra = false;
      for (size_t i = 5; i < cam.distortion.size(); ++i) extra |= cam.distortion[i] != 0.0;
      if (extra)
        y.Fail(r[d], d, "expected 4 or 5 radial-tangential coefficients; the rational or thin-prism "
                        "terms beyond k3 are not supported");
      cam.distortion.resize(5);
    }
    return cam;
  };
  rig.cam0 = camera("M1", "D1");
  rig.cam1 = camera("M2", "D2");
  const std::string unit = CalibrationYaml::Has(r, "unit") ? y.Text(r, "unit") : "";
  double scale = 0;
  if (unit == "m") scale = 1.0;
  if (unit == "cm") scale = 0.01;
  if (unit == "mm") scale = 0.001;
  if (scale == 0)
    y.Fail(CalibrationYaml::Has(r, "unit") ? r["unit"] : r, "unit",
           unit.empty() ? "missing; expected the unit of T (m, cm or mm): OpenCV's calibration keeps "
                          "the unit of the board's square size, which the file does not record"
                        : "expected m, cm or mm, got '" + unit + "'");
  const Eigen::Matrix3d rot = y.Matrix(r, "R", 3, 3);
  if ((rot * rot.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 ||
      rot.determinant() < 0)
    y.Fail(r["R"], "R", "expected a rotation matrix");
  rig.cam1_from_cam0.linear() = NearestRotation(rot);
  rig.cam1_from_cam0.translation() = scale * Eigen::Vector3d(y.Matrix(r, "T", 3, 1));
  const bool any = CalibrationYaml::Has(r, "R1") || CalibrationYaml::Has(r, "R2") ||
                   CalibrationYaml::Has(r, "P1") || CalibrationYaml::Has(r, "P2");
  if (any) {
    StereoRig::GivenRectification g;
    g.r0 = y.Matrix(r, "R1", 3, 3);
    g.r1 = y.Matrix(r, "R2", 3, 3);
    g.p0 = y.Matrix(r, "P1", 3, 4);
    g.p1 = y.Matrix(r, "P2", 3, 4);
    // P2's fourth column holds fx·Tx in T's unit.
    g.p1.col(3) *= scale;
    rig.given_rectification = g;
  }
  return rig;
}

StereoRig ReadOrbSlam3Settings(const std::string& path) {
  const CalibrationYaml y = CalibrationYaml::Read(path);
  const YAML::Node& r = y.root();
  StereoRig rig = NewRig(path, "orbslam3");
  const LensModel lens = ParseLens(y, r, "Camera.type");
  const int width = ImageSide(y, r, "Camera.width");
  const int height = ImageSide(y, r, "Camera.height");
  const auto camera = [&](const std::string& c) {
    CameraIntrinsics cam;
    cam.fx = y.Number(r, c + ".fx");
    cam.fy = y.Number(r, c + ".fy");
    cam.cx = y.Number(r, c + ".cx");
    cam.cy = y.Number(r, c + ".cy");
    cam.width = width;
    cam.height = height;
    cam.lens = lens;
    const std::vector<std::string> keys =
        lens == LensModel::kEquidistant ? std::vector<std::string>{"k1", "k2", "k3", "k4"}
                                        : std::vector<std::string>{"k1", "k2", "p1", "p2"};
    for (const std::string& k : keys) cam.distortion.push_back(y.Number(r, c + "." + k));
    if (lens == LensModel::kRadialTangential && CalibrationYaml::Has(r, c + ".k3"))
      cam.distortion.push_back(y.Number(r, c + ".k3"));
    return cam;
  };
  rig.cam0 = camera("Camera1");
  rig.cam1 = camera("Camera2");
  rig.cam1_from_cam0 = PoseFromMatrix(y, r, "Stereo.T_c1_c2").inverse();
  return rig;
}

StereoRig ReadRigCalibration(const std::string& path) {
  const CalibrationYaml y = CalibrationYaml::Read(path);
  const YAML::Node& r = y.root();
  if (CalibrationYaml::Has(r, "cam0") && CalibrationYaml::Has(r, "cam1")) return ReadKalibrCamchain(path);
  if (CalibrationYaml::Has(r, "M1")) return ReadOpenCvStereoCalibration(path);
  if (CalibrationYaml::Has(r, "Camera1.fx")) return ReadOrbSlam3Settings(path);
  if (CalibrationYaml::Has(r, "T_BS"))
    throw InputError(path, "is one camera's EuRoC sensor.yaml; expected a stereo calibration "
                           "(for the EuRoC layout, point cslam at the folder holding mav0/)");
  throw InputError(path, "is none of the known stereo calibrations: expected a Kalibr camchain "
                         "(cam0, cam1), an OpenCV stereo calibration (M1 D1 M2 D2 R T) or ORB-SLAM3 "
                         "stereo settings (Camera1.fx, ..., Stereo.T_c1_c2)");
}

std::string KalibrCamchainText(const StereoRig& rig) {
  std::ostringstream s;
  s << std::setprecision(12);
  s << "# The stereo rig as cslam read it from " << rig.source << " (" << rig.format
    << "), in Kalibr camchain.yaml form; translations in metres.\n";
  const auto matrix = [&](const Pose& p) {
    const Eigen::Matrix4d m = p.matrix();
    for (int i = 0; i < 4; ++i) {
      s << "  - [";
      for (int j = 0; j < 4; ++j) s << (j ? ", " : "") << m(i, j);
      s << "]\n";
    }
  };
  const auto camera = [&](const std::string& name, const CameraIntrinsics& c) {
    s << name << ":\n  camera_model: pinhole\n  intrinsics: [" << c.fx << ", " << c.fy << ", " << c.cx
      << ", " << c.cy << "]\n  distortion_model: " << NameOf(kLensModelNames, c.lens)
      << "\n  distortion_coeffs: [";
    for (size_t i = 0; i < c.distortion.size(); ++i) s << (i ? ", " : "") << c.distortion[i];
    s << "]\n  resolution: [" << c.width << ", " << c.height << "]\n";
  };
  camera("cam0", rig.cam0);
  if (rig.body_from_cam0) {
    s << "  T_cam_imu:\n";
    matrix(rig.body_from_cam0->inverse());
  }
  camera("cam1", rig.cam1);
  s << "  T_cn_cnm1:\n";
  matrix(rig.cam1_from_cam0);
  return s.str();
}

}  // namespace cslam
