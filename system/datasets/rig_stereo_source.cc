#include "system/datasets/rig_stereo_source.h"

#include <filesystem>
#include <stdexcept>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/rig_calibration.h"
#include "system/io/png_codec.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

cv::Mat Decode(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path, "expected an image file; it is missing");
  return ReadPng(path, PngPixels::kGreyAnyDepth);
}

}  // namespace

RigStereoSource::RigStereoSource(std::string name, std::string kind, StereoRig rig, RigFrames frames,
                                 std::optional<TimedPoses> body_truth)
    : name_(std::move(name)), kind_(std::move(kind)), rig_(std::move(rig)), frames_(std::move(frames)) {
  CheckStereoRig(rig_);
  if (frames_.left_files.empty()) throw InputError(name_, "contains no stereo pairs");
  rectifier_ = std::make_unique<StereoRectifier>(rig_);
  for (double t : frames_.times_s) timestamps_.push_back(t - frames_.times_s.front());

  // The first pair fixes how images are read: their size must be the calibration's, and a
  // 16-bit image is brought to 8 bits by the shift its brightest pixel needs.
  const cv::Mat first = Decode(frames_.left_files.front());
  if (first.cols != rig_.cam0.width || first.rows != rig_.cam0.height)
    throw InputError(frames_.left_files.front(),
                     "expected a " + std::to_string(rig_.cam0.width) + "x" + std::to_string(rig_.cam0.height) +
                         " image as the calibration says (" + rig_.source + "), got " +
                         std::to_string(first.cols) + "x" + std::to_string(first.rows) +
                         ": is the calibration for this camera and resolution?");
  if (first.depth() == CV_16U) {
    double hi = 0;
    cv::minMaxLoc(first, nullptr, &hi);
    int bits = 8;
    while (bits < 16 && hi >= double(1 << bits)) ++bits;
    image_shift_ = bits - 8;
    GetLogger("system")->warn("{}: 16-bit images (brightest pixel {} in the first one): converted to "
                              "8 bits (divided by 2^{})",
                              name_, hi, image_shift_);
  }
  LoadRaw(0);

  if (body_truth) {
    const std::vector<Pose> world_from_body = InterpolatePoses(*body_truth, frames_.times_s);
    Pose body_from_rect0 = Pose::Identity();
    body_from_rect0.linear() = rectifier_->rect0_from_cam0().transpose();
    if (rig_.body_from_cam0) body_from_rect0 = *rig_.body_from_cam0 * body_from_rect0;
    std::vector<Pose> gt;
    for (const Pose& p : world_from_body) gt.push_back(p * body_from_rect0);
    const Pose first_inv = gt.front().inverse();
    for (Pose& p : gt) p = first_inv * p;
    ground_truth_ = std::move(gt);
  }
  GetLogger("system")->info("{} ({}): {} pairs {}x{}, {} calibration {}, {}", name_, kind_, size(),
                            rig_.cam0.width, rig_.cam0.height, rig_.format, rig_.source,
                            body_truth ? "ground truth from " + body_truth->path : std::string("no ground truth"));
}

cv::Mat RigStereoSource::LoadImage(const std::string& path) const {
  cv::Mat image = Decode(path);
  if (image.cols != rig_.cam0.width || image.rows != rig_.cam0.height)
    throw InputError(path, "expected a " + std::to_string(rig_.cam0.width) + "x" +
                               std::to_string(rig_.cam0.height) + " image, got " + std::to_string(image.cols) +
                               "x" + std::to_string(image.rows));
  if (image.depth() == CV_16U) {
    cv::Mat out;
    image.convertTo(out, CV_8U, 1.0 / double(1 << image_shift_));
    return out;
  }
  return image;
}

StereoFrame RigStereoSource::LoadRaw(int index) const {
  if (index < 0 || index >= size())
    throw std::out_of_range("stereo frame " + std::to_string(index) + " is out of range [0, " +
                            std::to_string(size()) + ")");
  StereoFrame frame;
  frame.index = index;
  frame.timestamp = timestamps_[static_cast<size_t>(index)];
  frame.left = LoadImage(frames_.left_files[static_cast<size_t>(index)]);
  frame.right = LoadImage(frames_.right_files[static_cast<size_t>(index)]);
  return frame;
}

StereoFrame RigStereoSource::Load(int index) const {
  StereoFrame frame = LoadRaw(index);
  const cv::Mat raw_left = frame.left, raw_right = frame.right;
  // remap cannot work in place: fresh outputs.
  frame.left = cv::Mat();
  frame.right = cv::Mat();
  rectifier_->Rectify(raw_left, raw_right, &frame.left, &frame.right);
  return frame;
}

std::vector<std::pair<std::string, std::string>> RigStereoSource::DescriptionFiles() const {
  return {{"rig.yaml", KalibrCamchainText(rig_)}, {"rectified.yaml", rectifier_->RectifiedYamlText()}};
}

}  // namespace cslam
