#pragma once
// A user's own stereo rig as a StereoSource: raw image pairs, the rig's calibration, the
// rectification computed once and applied in Load(), and ground truth of the body frame
// carried to the rectified left camera. The layout readers (asl_layout.h, stereo_folder.h)
// find the files; this class does the rest the same way for all of them.
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "system/datasets/stereo_rectifier.h"
#include "system/datasets/stereo_rig.h"
#include "system/datasets/stereo_source.h"
#include "system/datasets/timed_poses.h"

namespace cslam {

/// The raw pairs a layout reader found.
struct RigFrames {
  std::vector<std::string> left_files, right_files;
  std::vector<double> times_s;  ///< per pair, on the ground truth's clock, strictly increasing
};

/// See the file comment.
class RigStereoSource : public StereoSource {
 public:
  /// Checks the rig (CheckStereoRig), builds the rectification, decodes pair 0 to check the
  /// images' size against the calibration, and interpolates `body_truth` (world_from_body, or
  /// world_from_cam0 when the rig has no body_from_cam0) at the image times. Throws InputError
  /// naming the file on any problem.
  RigStereoSource(std::string name, std::string kind, StereoRig rig, RigFrames frames,
                  std::optional<TimedPoses> body_truth);

  std::string name() const override { return name_; }
  std::string kind() const override { return kind_; }
  const StereoCamera& camera() const override { return rectifier_->camera(); }
  int size() const override { return static_cast<int>(frames_.left_files.size()); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  /// The rectified pair.
  StereoFrame Load(int index) const override;
  std::optional<std::vector<Pose>> GroundTruth() const override { return ground_truth_; }
  std::vector<std::pair<std::string, std::string>> DescriptionFiles() const override;

  /// The pair as recorded, before rectification (8-bit grey).
  StereoFrame LoadRaw(int index) const;
  const StereoRig& rig() const { return rig_; }
  const StereoRectifier& rectifier() const { return *rectifier_; }

 private:
  cv::Mat LoadImage(const std::string& path) const;

  std::string name_, kind_;
  StereoRig rig_;
  RigFrames frames_;
  std::unique_ptr<StereoRectifier> rectifier_;
  std::vector<double> timestamps_;
  int image_shift_ = 0;  ///< bits to drop from 16-bit images (0: 8-bit images)
  std::optional<std::vector<Pose>> ground_truth_;
};

}  // namespace cslam
