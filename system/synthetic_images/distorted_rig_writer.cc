#include "system/synthetic_images/distorted_rig_writer.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>

#include "core/atomic_file.h"
#include "core/options_reader.h"
#include "system/datasets/rig_calibration.h"
#include "system/io/image_io.h"
#include "system/synthetic_images/synthetic_renderer.h"

namespace cslam {

namespace fs = std::filesystem;

void DistortedRigOptions::Check() const {
  CheckOption(lens != LensModel::kNone, "lens", "must be radtan or equidistant", 0);
  CheckOption(std::abs(right_rotation_deg) <= 10, "right_rotation_deg", "must be within +-10 degrees",
              right_rotation_deg);
  CheckOption(supersample >= 1 && supersample <= 4, "supersample", "must be in [1, 4]", supersample);
}

namespace {

constexpr double kDeg = M_PI / 180.0;

// Where the rays through the raw pixel positions `pixels` meet the image plane of the pinhole
// camera `k_rect` in the rectified frame: undistort, rotate into the rectified frame, project.
std::vector<cv::Point2f> RawToRectified(const CameraIntrinsics& raw, const Eigen::Matrix3d& rect_from_raw,
                                        const std::vector<cv::Point2f>& pixels, const cv::Mat& k_rect) {
  const cv::Mat k = (cv::Mat_<double>(3, 3) << raw.fx, 0, raw.cx, 0, raw.fy, raw.cy, 0, 0, 1);
  cv::Mat r(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.at<double>(i, j) = rect_from_raw(i, j);
  std::vector<cv::Point2f> out;
  // Undistortion is iterative: OpenCV's default 5 iterations leave pixels of error at the
  // corners of a strong lens (k1 = -0.28), which would make the images disagree with the
  // calibration they come with. Iterate to convergence.
  const cv::TermCriteria converge(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12);
  if (raw.lens == LensModel::kEquidistant)
    cv::fisheye::undistortPoints(pixels, out, k, raw.distortion, r, k_rect, converge);
  else
    cv::undistortPoints(pixels, out, k, raw.distortion, r, k_rect, converge);
  return out;
}

// Raw pixel positions: the centres of a k x k grid of sub-pixels of every pixel, one list per
// sub-pixel (a raw pixel's value is the mean over its footprint).
std::vector<std::vector<cv::Point2f>> SubPixelGrids(int width, int height, int k) {
  std::vector<std::vector<cv::Point2f>> grids;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const float du = static_cast<float>((j + 0.5) / k - 0.5), dv = static_cast<float>((i + 0.5) / k - 0.5);
      std::vector<cv::Point2f>& g = grids.emplace_back();
      g.reserve(static_cast<size_t>(width * height));
      for (int v = 0; v < height; ++v)
        for (int u = 0; u < width; ++u) g.emplace_back(static_cast<float>(u) + du, static_cast<float>(v) + dv);
    }
  return grids;
}

cv::Mat KOf(const StereoCamera& c) { return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1); }

// The pinhole camera in the rectified frame, `k` times finer than the rendered one, whose
// image holds every ray of both raw cameras' pixels (with a margin for their footprints).
StereoCamera FineCamera(const StereoCamera& rendered, const std::vector<cv::Point2f>& raw_rays_a,
                        const std::vector<cv::Point2f>& raw_rays_b, int k) {
  float lo_x = 0, lo_y = 0, hi_x = static_cast<float>(rendered.width - 1), hi_y = static_cast<float>(rendered.height - 1);
  for (const auto* rays : {&raw_rays_a, &raw_rays_b})
    for (const cv::Point2f& q : *rays) {
      lo_x = std::min(lo_x, q.x);
      lo_y = std::min(lo_y, q.y);
      hi_x = std::max(hi_x, q.x);
      hi_y = std::max(hi_y, q.y);
    }
  // A raw pixel's footprint reaches past its centre's ray by half a raw pixel, which a strong
  // lens's corners stretch to a few rendered pixels.
  constexpr int kMarginPx = 8;
  const int left = static_cast<int>(std::ceil(-lo_x)) + kMarginPx, top = static_cast<int>(std::ceil(-lo_y)) + kMarginPx;
  const int right = static_cast<int>(std::ceil(hi_x - (rendered.width - 1))) + kMarginPx;
  const int bottom = static_cast<int>(std::ceil(hi_y - (rendered.height - 1))) + kMarginPx;
  StereoCamera fine = rendered;
  fine.fx = k * rendered.fx;
  fine.fy = k * rendered.fy;
  fine.cx = k * (rendered.cx + left + 0.5) - 0.5;
  fine.cy = k * (rendered.cy + top + 0.5) - 0.5;
  fine.width = k * (rendered.width + left + right);
  fine.height = k * (rendered.height + top + bottom);
  return fine;
}

// For each sub-pixel grid, the pair of remap tables into the fine rendering.
struct FootprintMaps {
  std::vector<cv::Mat> x, y;
};

FootprintMaps MapsInto(const CameraIntrinsics& raw, const Eigen::Matrix3d& rect_from_raw,
                       const std::vector<std::vector<cv::Point2f>>& grids, const StereoCamera& fine) {
  FootprintMaps maps;
  for (const auto& grid : grids) {
    const std::vector<cv::Point2f> q = RawToRectified(raw, rect_from_raw, grid, KOf(fine));
    cv::Mat mx(raw.height, raw.width, CV_32FC1), my(raw.height, raw.width, CV_32FC1);
    for (int v = 0; v < raw.height; ++v)
      for (int u = 0; u < raw.width; ++u) {
        const cv::Point2f& p = q[static_cast<size_t>(v * raw.width + u)];
        mx.at<float>(v, u) = p.x;
        my.at<float>(v, u) = p.y;
      }
    maps.x.push_back(mx);
    maps.y.push_back(my);
  }
  return maps;
}

// The raw image: each pixel the mean of the fine rendering over its sub-pixels.
cv::Mat RawImage(const cv::Mat& fine_image, const FootprintMaps& maps) {
  cv::Mat sum = cv::Mat::zeros(maps.x[0].size(), CV_32FC1), sample, sample_f;
  for (size_t s = 0; s < maps.x.size(); ++s) {
    cv::remap(fine_image, sample, maps.x[s], maps.y[s], cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    sample.convertTo(sample_f, CV_32FC1);
    sum += sample_f;
  }
  cv::Mat raw;
  sum.convertTo(raw, CV_8UC1, 1.0 / static_cast<double>(maps.x.size()));
  return raw;
}

bool Inside(const cv::Mat& mx, const cv::Mat& my, int width, int height);

// Whether every pixel of the rendered camera, rotated into the raw camera, lands inside the
// raw image.
bool CoversRendered(const CameraIntrinsics& raw, const Eigen::Matrix3d& rect_from_raw, const StereoCamera& rendered) {
  const cv::Mat k = (cv::Mat_<double>(3, 3) << raw.fx, 0, raw.cx, 0, raw.fy, raw.cy, 0, 0, 1);
  const cv::Mat p = (cv::Mat_<double>(3, 3) << rendered.fx, 0, rendered.cx, 0, rendered.fy, rendered.cy, 0, 0, 1);
  cv::Mat r(3, 3, CV_64F), mx, my;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.at<double>(i, j) = rect_from_raw(i, j);
  const cv::Size size(rendered.width, rendered.height);
  if (raw.lens == LensModel::kEquidistant)
    cv::fisheye::initUndistortRectifyMap(k, raw.distortion, r, p, size, CV_32FC1, mx, my);
  else
    cv::initUndistortRectifyMap(k, raw.distortion, r, p, size, CV_32FC1, mx, my);
  return Inside(mx, my, raw.width, raw.height);
}

bool Inside(const cv::Mat& mx, const cv::Mat& my, int width, int height) {
  double lo_x, hi_x, lo_y, hi_y;
  cv::minMaxLoc(mx, &lo_x, &hi_x);
  cv::minMaxLoc(my, &lo_y, &hi_y);
  return lo_x >= 0 && lo_y >= 0 && hi_x <= width - 1 && hi_y <= height - 1;
}

std::string EurocSensorYaml(const CameraIntrinsics& c, const Pose& body_from_cam) {
  std::ostringstream s;
  s << std::setprecision(15) << "%YAML:1.0\nsensor_type: camera\ncomment: cslam synthetic distorted rig\nT_BS:\n"
    << "  cols: 4\n  rows: 4\n  data: [";
  const Eigen::Matrix4d m = body_from_cam.matrix();
  for (int i = 0; i < 16; ++i) s << (i ? ", " : "") << m(i / 4, i % 4);
  s << "]\nrate_hz: 10\nresolution: [" << c.width << ", " << c.height << "]\ncamera_model: pinhole\nintrinsics: ["
    << c.fx << ", " << c.fy << ", " << c.cx << ", " << c.cy << "]\ndistortion_model: "
    << (c.lens == LensModel::kEquidistant ? "equidistant" : "radial-tangential") << "\ndistortion_coefficients: [";
  for (size_t i = 0; i < c.distortion.size(); ++i) s << (i ? ", " : "") << c.distortion[i];
  s << "]\n";
  return s.str();
}

std::string OpenCvMatrix(const std::string& name, const Eigen::MatrixXd& m) {
  std::ostringstream s;
  s << std::setprecision(15) << name << ": !!opencv-matrix\n  rows: " << m.rows() << "\n  cols: " << m.cols()
    << "\n  dt: d\n  data: [";
  for (int i = 0; i < m.rows(); ++i)
    for (int j = 0; j < m.cols(); ++j) s << (i || j ? ", " : "") << m(i, j);
  s << "]\n";
  return s.str();
}

Eigen::MatrixXd K(const CameraIntrinsics& c) {
  Eigen::Matrix3d k;
  k << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1;
  return k;
}

Eigen::MatrixXd Row(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::RowVectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

std::string OpenCvText(const StereoRig& rig) {
  const std::string model = rig.cam0.lens == LensModel::kEquidistant ? "fisheye" : "radtan";
  return "%YAML:1.0\n---\nimage_width: " + std::to_string(rig.cam0.width) + "\nimage_height: " +
         std::to_string(rig.cam0.height) + "\nunit: m\ndistortion_model: " + model + "\n" + OpenCvMatrix("M1", K(rig.cam0)) +
         OpenCvMatrix("D1", Row(rig.cam0.distortion)) + OpenCvMatrix("M2", K(rig.cam1)) +
         OpenCvMatrix("D2", Row(rig.cam1.distortion)) + OpenCvMatrix("R", rig.cam1_from_cam0.linear()) +
         OpenCvMatrix("T", rig.cam1_from_cam0.translation());
}

// The same rig with the rectification that gives back the rendered camera exactly.
std::string OpenCvRectifiedText(const StereoRig& rig, const Eigen::Matrix3d& rect0_from_raw0,
                                const Eigen::Matrix3d& rect1_from_raw1, const StereoCamera& rendered) {
  Eigen::Matrix<double, 3, 4> p0 = Eigen::Matrix<double, 3, 4>::Zero();
  p0(0, 0) = rendered.fx;
  p0(1, 1) = rendered.fy;
  p0(0, 2) = rendered.cx;
  p0(1, 2) = rendered.cy;
  p0(2, 2) = 1;
  Eigen::Matrix<double, 3, 4> p1 = p0;
  p1(0, 3) = -rendered.fx * rendered.baseline;
  return OpenCvText(rig) + OpenCvMatrix("R1", rect0_from_raw0) + OpenCvMatrix("R2", rect1_from_raw1) +
         OpenCvMatrix("P1", p0) + OpenCvMatrix("P2", p1);
}

std::string OrbSlam3Text(const StereoRig& rig) {
  std::ostringstream s;
  s << std::setprecision(15) << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \""
    << (rig.cam0.lens == LensModel::kEquidistant ? "KannalaBrandt8" : "PinHole") << "\"\n";
  const std::vector<std::string> names = rig.cam0.lens == LensModel::kEquidistant
                                             ? std::vector<std::string>{"k1", "k2", "k3", "k4"}
                                             : std::vector<std::string>{"k1", "k2", "p1", "p2", "k3"};
  for (const auto& [n, c] : {std::pair<std::string, const CameraIntrinsics*>{"Camera1", &rig.cam0}, {"Camera2", &rig.cam1}}) {
    s << n << ".fx: " << c->fx << "\n" << n << ".fy: " << c->fy << "\n" << n << ".cx: " << c->cx << "\n"
      << n << ".cy: " << c->cy << "\n";
    for (size_t i = 0; i < c->distortion.size() && i < names.size(); ++i) s << n << "." << names[i] << ": " << c->distortion[i] << "\n";
  }
  s << "Camera.width: " << rig.cam0.width << "\nCamera.height: " << rig.cam0.height << "\n"
    << OpenCvMatrix("Stereo.T_c1_c2", rig.cam1_from_cam0.inverse().matrix());
  return s.str();
}

}  // namespace

std::string WriteDistortedRig(const SyntheticSequence& sequence, const std::string& dir,
                              const DistortedRigOptions& options, const SyntheticRenderOptions& render) {
  options.Check();
  render.Check();
  const StereoCamera& cam = sequence.camera;
  const bool fisheye = options.lens == LensModel::kEquidistant;
  const fs::path out = fs::path(dir) / (fisheye ? "rig_equidistant" : "rig_radtan");

  // Raw cameras: slightly different principal points and lenses, rotated off the rectified
  // frame (left by under a degree, right by options.right_rotation_deg about y and less about x, z).
  StereoRig rig;
  rig.source = out.string();
  rig.format = "euroc";
  rig.cam0.lens = rig.cam1.lens = options.lens;
  rig.cam0.distortion = fisheye ? std::vector<double>{-0.013, 0.004, -0.002, 0.0004}
                                : std::vector<double>{-0.28, 0.074, 0.0002, 0.00002};
  rig.cam1.distortion = fisheye ? std::vector<double>{-0.011, 0.003, -0.0015, 0.0003}
                                : std::vector<double>{-0.27, 0.070, -0.0001, -0.00003};
  for (CameraIntrinsics* c : {&rig.cam0, &rig.cam1}) {
    c->width = cam.width;
    c->height = cam.height;
  }
  rig.cam0.cx = cam.cx + 3.0;
  rig.cam0.cy = cam.cy - 2.0;
  rig.cam1.cx = cam.cx - 4.0;
  rig.cam1.cy = cam.cy + 1.5;
  const Eigen::Matrix3d rect0_from_raw0 = ExpSO3(Eigen::Vector3d(0.3, -0.5, 0.2) * kDeg);
  const Eigen::Matrix3d rect1_from_raw1 =
      ExpSO3(Eigen::Vector3d(0.4, options.right_rotation_deg, -0.3) * kDeg);
  // The raw focal length: the largest (in 2 % steps down from the rendered one) at which the
  // raw image still sees every rendered pixel, so that rectifying back to the rendered camera
  // (opencv_rectified.yml) leaves no pixel without data.
  for (double scale = 1.0;; scale /= 1.02) {
    rig.cam0.fx = rig.cam0.fy = scale * cam.fx;
    rig.cam1.fx = rig.cam1.fy = scale * cam.fx * 1.003;
    if (CoversRendered(rig.cam0, rect0_from_raw0, cam) && CoversRendered(rig.cam1, rect1_from_raw1, cam)) break;
    if (scale < 0.25) throw InputError(dir, "cannot fit the rendered images inside the distorted rig's");
  }
  // The raw images are drawn from a rendering of the rectified frame k times finer than the
  // rendered camera and wide enough for every raw ray: resampling the rendered images instead
  // would blur them once more than a real rig's images are blurred (the rectification is the
  // only resampling a real rig goes through).
  const int k = options.supersample;
  const std::vector<std::vector<cv::Point2f>> grids = SubPixelGrids(cam.width, cam.height, k);
  const std::vector<cv::Point2f> centres = SubPixelGrids(cam.width, cam.height, 1)[0];
  const StereoCamera fine = FineCamera(cam, RawToRectified(rig.cam0, rect0_from_raw0, centres, KOf(cam)),
                                       RawToRectified(rig.cam1, rect1_from_raw1, centres, KOf(cam)), k);
  const FootprintMaps maps0 = MapsInto(rig.cam0, rect0_from_raw0, grids, fine);
  const FootprintMaps maps1 = MapsInto(rig.cam1, rect1_from_raw1, grids, fine);
  SyntheticRenderOptions fine_render = render;
  fine_render.supersample = 1;
  SyntheticRenderer renderer(sequence.geometry, fine, fine_render);
  Pose body_from_cam0 = Pose::Identity(), body_from_cam1 = Pose::Identity();
  body_from_cam0.linear() = rect0_from_raw0;
  body_from_cam1.linear() = rect1_from_raw1;
  body_from_cam1.translation() = Eigen::Vector3d(cam.baseline, 0, 0);
  rig.cam1_from_cam0 = body_from_cam1.inverse() * body_from_cam0;
  rig.body_from_cam0 = body_from_cam0;

  std::string csv = "#timestamp [ns],filename\n", gt = "# timestamp(s) tx ty tz qx qy qz qw (the rendered left camera)\n";
  for (int f = 0; f < sequence.num_frames(); ++f) {
    const long long ns = 1000000000LL + std::llround(sequence.timestamps[static_cast<size_t>(f)] * 1e9);
    const std::string name = std::to_string(ns) + ".png";
    csv += std::to_string(ns) + "," + name + "\n";
    const RenderedStereoFrame frame = renderer.Render(sequence, f);
    WritePng(RawImage(frame.left, maps0), (out / "mav0" / "cam0" / "data" / name).string());
    WritePng(RawImage(frame.right, maps1), (out / "mav0" / "cam1" / "data" / name).string());
    const Pose& p = sequence.world_from_cam[static_cast<size_t>(f)];
    const Eigen::Quaterniond q(p.linear());
    char line[256];
    std::snprintf(line, sizeof(line), "%.9f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", static_cast<double>(ns) * 1e-9,
                  p.translation().x(), p.translation().y(), p.translation().z(), q.x(), q.y(), q.z(), q.w());
    gt += line;
  }
  const auto text = [&](const fs::path& p, const std::string& t) {
    WriteFileAtomically(p.string(), [&](std::ostream& s) { s << t; });
  };
  for (int c = 0; c < 2; ++c) {
    const fs::path cam_dir = out / "mav0" / (c ? "cam1" : "cam0");
    text(cam_dir / "data.csv", csv);
    text(cam_dir / "sensor.yaml", EurocSensorYaml(c ? rig.cam1 : rig.cam0, c ? body_from_cam1 : body_from_cam0));
  }
  text(out / "camchain.yaml", KalibrCamchainText(rig));
  text(out / "opencv_stereo.yml", OpenCvText(rig));
  text(out / "orbslam3_settings.yaml", OrbSlam3Text(rig));
  text(out / "opencv_rectified.yml", OpenCvRectifiedText(rig, rect0_from_raw0, rect1_from_raw1, cam));
  // Where the rendered sequence's truth is, for a run rectified back to the rendered camera.
  text(out / "synthetic_truth.txt", "..\n");
  text(out / "groundtruth_tum.txt", gt);
  return out.string();
}

}  // namespace cslam
