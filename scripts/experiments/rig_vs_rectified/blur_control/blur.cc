// blur: in-place Gaussian blur of 8-bit grey PNGs, or gradient-energy ratio table.
// usage: blur apply SIGMA file...       (overwrites each file with its blurred version)
//        blur ratio file SIGMA...       (prints sigma ratio; border 2 px dropped)
#include <opencv2/opencv.hpp>
#include <cstdio>
#include <cstdlib>
#include <string>
static double genergy(const cv::Mat& f) {
  double s = 0;
  for (int y = 2; y < f.rows - 2; ++y)
    for (int x = 2; x < f.cols - 2; ++x) {
      double gx = 0.5 * (f.at<float>(y, x + 1) - f.at<float>(y, x - 1));
      double gy = 0.5 * (f.at<float>(y + 1, x) - f.at<float>(y - 1, x));
      s += gx * gx + gy * gy;
    }
  return s;
}
int main(int argc, char** argv) {
  if (argc < 4) { fprintf(stderr, "usage\n"); return 2; }
  std::string mode = argv[1];
  if (mode == "apply") {
    double sigma = atof(argv[2]);
    for (int i = 3; i < argc; ++i) {
      cv::Mat im = cv::imread(argv[i], cv::IMREAD_UNCHANGED);
      if (im.empty() || im.type() != CV_8UC1) { fprintf(stderr, "bad image %s\n", argv[i]); return 1; }
      cv::Mat f, b, out;
      im.convertTo(f, CV_32F);
      cv::GaussianBlur(f, b, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT101);
      b.convertTo(out, CV_8U);  // saturate_cast rounds to nearest
      if (!cv::imwrite(argv[i], out)) { fprintf(stderr, "write fail %s\n", argv[i]); return 1; }
    }
    return 0;
  } else if (mode == "ratio") {
    cv::Mat im = cv::imread(argv[2], cv::IMREAD_UNCHANGED);
    if (im.empty() || im.type() != CV_8UC1) { fprintf(stderr, "bad image\n"); return 1; }
    cv::Mat f; im.convertTo(f, CV_32F);
    double e0 = genergy(f);
    for (int i = 3; i < argc; ++i) {
      double sigma = atof(argv[i]);
      cv::Mat b, b8, bf;
      cv::GaussianBlur(f, b, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT101);
      b.convertTo(b8, CV_8U); b8.convertTo(bf, CV_32F);  // ratio of the rounded 8-bit image actually written
      double ef = genergy(b);
      printf("%s %.2f %.4f %.4f\n", argv[2], sigma, genergy(bf) / e0, ef / e0);
    }
    return 0;
  }
  return 2;
}
