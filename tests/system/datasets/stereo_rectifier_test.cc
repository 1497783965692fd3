// Rectification of real rigs: the pinhole pair against another project's OpenCV reference
// images, the fisheye pair's rows, no invalid pixel in the default framing, and an already
// rectified rig passed through untouched.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <iostream>

#include "system/datasets/rig_calibration.h"
#include "system/datasets/rig_image_check.h"
#include "system/datasets/stereo_rectifier.h"
#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

fs::path Kimera() { return testing::SharedData() / "stereo_rectification" / "kimera_fisheye_pair"; }

cv::Mat Grey(const fs::path& p) {
  cv::Mat m = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw std::runtime_error("test data not found: " + p.string());
  return m;
}

StereoRig PinholeRig() {
  return ReadEurocSensorPair((Kimera() / "sensorLeft.yaml").string(), (Kimera() / "sensorRight.yaml").string());
}
StereoRig FisheyeRig() {
  return ReadEurocSensorPair((Kimera() / "left_sensor_fisheye.yaml").string(),
                             (Kimera() / "right_sensor_fisheye.yaml").string());
}

// Share of the pixels inside `valid` where the two images differ by at most one grey level.
double ShareWithinOneLevel(const cv::Mat& a, const cv::Mat& b, const cv::Mat& valid) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const double n = cv::countNonZero(valid);
  const double close = cv::countNonZero((diff <= 1) & valid);
  return close / n;
}

// Pixels whose whole bilinear neighbourhood lies inside the raw image: a white image
// rectified stays white exactly there.
cv::Mat ValidPixels(const StereoRectifier& r, bool left) {
  const cv::Mat white(r.camera().height, r.camera().width, CV_8UC1, cv::Scalar(255));
  cv::Mat l, rr;
  r.Rectify(white, white, &l, &rr);
  return (left ? l : rr) == 255;
}

// The shared folder's side-by-side reference is of the fisheye pair (its README says the
// pinhole pair; the pictures show the fisheye scene), rectified with OpenCV's fisheye
// functions at balance 0 (docs/experiments/2026-12-06-rectification-against-kimera-reference.md).
TEST(StereoRectifier, TheFisheyePairMatchesTheSideBySideReferenceToOneGreyLevel) {
  RectificationOptions opencv_framing;  // the reference kept OpenCV's framing, invalid corners too
  opencv_framing.exclude_invalid_pixels = false;
  const StereoRectifier r(FisheyeRig(), opencv_framing);
  cv::Mat left, right;
  r.Rectify(Grey(Kimera() / "left_fisheye_img_0.png"), Grey(Kimera() / "right_fisheye_img_0.png"), &left, &right);
  const cv::Mat side = Grey(Kimera() / "sidebyside_ref_img_0.png");
  ASSERT_EQ(side.cols, 2 * left.cols);
  const cv::Mat ref_left = side(cv::Rect(0, 0, left.cols, left.rows));
  const cv::Mat ref_right = side(cv::Rect(left.cols, 0, left.cols, left.rows));
  const double share_left = ShareWithinOneLevel(left, ref_left, ValidPixels(r, true));
  const double share_right = ShareWithinOneLevel(right, ref_right, ValidPixels(r, false));
  std::cout << "within one grey level of the reference: left " << share_left << ", right " << share_right << "\n";
  EXPECT_GE(share_left, 0.99);
  EXPECT_GE(share_right, 0.99);
}

TEST(StereoRectifier, TheDefaultFramingLeavesNoInvalidPixel) {
  for (const StereoRig& rig : {PinholeRig(), FisheyeRig()}) {
    const StereoRectifier r(rig);
    EXPECT_EQ(cv::countNonZero(~ValidPixels(r, true)), 0) << rig.source;
    EXPECT_EQ(cv::countNonZero(~ValidPixels(r, false)), 0) << rig.source;
  }
}

TEST(StereoRectifier, TheFisheyePairsRowsAgreeAfterRectification) {
  const StereoRectifier r(FisheyeRig());
  cv::Mat left, right;
  const cv::Mat raw_left = Grey(Kimera() / "left_fisheye_img_0.png"), raw_right = Grey(Kimera() / "right_fisheye_img_0.png");
  r.Rectify(raw_left, raw_right, &left, &right);
  const VerticalOffsets rect = MeasureVerticalOffsets(left, right);
  const VerticalOffsets raw = MeasureVerticalOffsets(raw_left, raw_right);
  std::cout << "fisheye vertical offsets: rectified median " << rect.median << " px, p90 " << rect.p90
            << " (" << rect.matches << " matches); raw median " << raw.median << " px\n";
  EXPECT_GE(rect.matches, 50);
  EXPECT_LE(rect.median, 0.5);
  EXPECT_NEAR(r.camera().baseline, 0.1262, 0.01);
}

TEST(StereoRectifier, AnAlreadyRectifiedRigPassesThroughBitForBit) {
  StereoRig rig;
  rig.source = "test";
  for (CameraIntrinsics* c : {&rig.cam0, &rig.cam1}) *c = {718.856, 718.856, 607.1928, 185.2157, 1241, 376, LensModel::kNone, {}};
  rig.cam1_from_cam0.translation() = Eigen::Vector3d(-0.5371657, 0, 0);
  const StereoRectifier r(rig);
  EXPECT_TRUE(r.identity());
  EXPECT_DOUBLE_EQ(r.camera().baseline, 0.5371657);
  EXPECT_DOUBLE_EQ(r.camera().cx, 607.1928);
  cv::Mat img(376, 1241, CV_8UC1), out_l, out_r;
  cv::randu(img, 0, 255);
  r.Rectify(img, img, &out_l, &out_r);
  EXPECT_EQ(cv::countNonZero(out_l != img), 0);
}

}  // namespace
}  // namespace cslam
