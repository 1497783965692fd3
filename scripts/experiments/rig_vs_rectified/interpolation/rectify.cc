// Rectify a raw ASL rig (mav0/cam0,cam1) with opencv_rectified.yml into KITTI-style image_0/image_1.
// usage: rectify <rig_dir> <out_seq_00_dir> <linear|cubic|lanczos>
#include <opencv2/opencv.hpp>
#include <opencv2/calib3d.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>
namespace fs = std::filesystem;
static std::vector<fs::path> List(const fs::path& d) {
  std::vector<fs::path> v;
  for (auto& e : fs::directory_iterator(d)) if (e.path().extension() == ".png") v.push_back(e.path());
  std::sort(v.begin(), v.end(), [](const fs::path& a, const fs::path& b) {
    return std::stoll(a.stem().string()) < std::stoll(b.stem().string()); });
  return v;
}
int main(int argc, char** argv) {
  if (argc != 4) { fprintf(stderr, "usage\n"); return 2; }
  fs::path rig = argv[1], out = argv[2]; std::string ip = argv[3];
  int interp = ip == "linear" ? cv::INTER_LINEAR : ip == "cubic" ? cv::INTER_CUBIC : ip == "lanczos" ? cv::INTER_LANCZOS4 : -1;
  if (interp < 0) { fprintf(stderr, "bad interp\n"); return 2; }
  cv::FileStorage fsr((rig / "opencv_rectified.yml").string(), cv::FileStorage::READ);
  std::string model; fsr["distortion_model"] >> model;
  int w = (int)fsr["image_width"], h = (int)fsr["image_height"];
  cv::Mat M[2], D[2], R[2], P[2];
  fsr["M1"] >> M[0]; fsr["D1"] >> D[0]; fsr["R1"] >> R[0]; fsr["P1"] >> P[0];
  fsr["M2"] >> M[1]; fsr["D2"] >> D[1]; fsr["R2"] >> R[1]; fsr["P2"] >> P[1];
  cv::Mat mx[2], my[2];
  for (int c = 0; c < 2; ++c) {
    if (model == "fisheye" || model == "equidistant")
      cv::fisheye::initUndistortRectifyMap(M[c], D[c], R[c], P[c], cv::Size(w, h), CV_32FC1, mx[c], my[c]);
    else if (model == "radtan")
      cv::initUndistortRectifyMap(M[c], D[c], R[c], P[c], cv::Size(w, h), CV_32FC1, mx[c], my[c]);
    else { fprintf(stderr, "unknown model %s\n", model.c_str()); return 2; }
    // Same as cslam's rectifier for bilinear (fixed-point maps); float maps otherwise.
    if (interp == cv::INTER_LINEAR) { cv::Mat a, b; cv::convertMaps(mx[c], my[c], a, b, CV_16SC2); mx[c] = a; my[c] = b; }
  }
  fprintf(stderr, "%s model=%s %dx%d interp=%s\n", rig.c_str(), model.c_str(), w, h, ip.c_str());
  for (int c = 0; c < 2; ++c) {
    auto files = List(rig / "mav0" / ("cam" + std::to_string(c)) / "data");
    fs::path od = out / ("image_" + std::to_string(c));
    fs::create_directories(od);
    for (size_t i = 0; i < files.size(); ++i) {
      cv::Mat raw = cv::imread(files[i].string(), cv::IMREAD_UNCHANGED);
      if (raw.type() != CV_8UC1 || raw.cols != w || raw.rows != h) { fprintf(stderr, "bad image %s\n", files[i].c_str()); return 1; }
      cv::Mat r; cv::remap(raw, r, mx[c], my[c], interp, cv::BORDER_CONSTANT);
      char name[32]; snprintf(name, sizeof name, "%06zu.png", i);
      cv::imwrite((od / name).string(), r);
    }
    fprintf(stderr, "cam%d: %zu images\n", c, files.size());
  }
  return 0;
}
