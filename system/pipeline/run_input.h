#pragma once
// Whatever `cslam run INPUT` was pointed at, opened into one shape: a camera, per-frame
// timestamps, either stereo images (a frontend makes the tracklets) or ready-made tracklets
// (a synthetic sequence without images), and whatever ground truth the dataset carries.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "system/datasets/stereo_source.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {

/// What `cslam run` was pointed at; picks the recommended configuration and the metrics.
enum class InputKind {
  kKittiRaw,         ///< a KITTI raw drive (tracklet boxes label the moving landmarks)
  kKittiOdometry,    ///< a KITTI odometry sequence
  kSynthetic,        ///< a synthetic sequence replayed as tracklets (no images)
  kSyntheticImages,  ///< a synthetic sequence with rendered stereo images
  kEuroc,            ///< an ASL-layout sequence (EuRoC, TUM-VI), rectified as it is read
  kStereoFolder,     ///< a plain left/ right/ folder with a --calib file, rectified as read
};
/// The kinds' names in logs, messages and run outputs (StereoSource::kind() uses the same).
inline constexpr EnumName<InputKind> kInputKindNames[] = {
    {InputKind::kKittiRaw, "kitti_raw"},
    {InputKind::kKittiOdometry, "kitti_odometry"},
    {InputKind::kSynthetic, "synthetic"},
    {InputKind::kSyntheticImages, "synthetic_images"},
    {InputKind::kEuroc, "euroc"},
    {InputKind::kStereoFolder, "stereo_folder"},
};

/// An opened input sequence; see the file comment.
struct RunInput {
  std::string path;
  std::string name;   ///< sequence name for metrics.json
  InputKind kind = InputKind::kSynthetic;
  StereoCamera camera;
  std::vector<double> timestamps;                     ///< seconds, per frame
  std::unique_ptr<StereoSource> images;               ///< null: observations are given
  std::optional<TrackletTable> observations;          ///< ready-made tracklets (synthetic)
  std::optional<std::vector<Pose>> gt_world_from_cam; ///< per frame, world = camera at frame 0
  std::optional<SyntheticSequence> synthetic;         ///< full synthetic ground truth
  /// The synthetic sequence folder whose object-id images label the landmarks ("" = path); a
  /// rig re-recorded from it (cslam synth --rig) lives elsewhere.
  std::string synthetic_dir;
  std::vector<std::vector<ObjectBox>> gt_boxes;       ///< [frame] labelled boxes (KITTI raw)
  std::optional<GroundTruthCrossCheck> gt_cross_check; ///< the ground truth's own second estimate
  /// (name, text) files the run writes to say how it read the input (rig.yaml, rectified.yaml).
  std::vector<std::pair<std::string, std::string>> description_files;
  bool color = false;  ///< KITTI raw: the colour pair image_02/03 is the one read
  /// What opening decided on its own (the colour pair of a drive without the grey one), for
  /// the run's log: the input is opened before the log file exists.
  std::vector<std::string> notes;

  int num_frames() const { return static_cast<int>(timestamps.size()); }
  bool has_images() const { return images != nullptr; }
};

/// Options of the input stage.
struct InputOptions {
  bool color = false;     ///< KITTI raw: use the colour pair image_02/03 (converted to grey)
  int max_frames = 0;     ///< 0 = all; otherwise only the first max_frames
  bool use_images = true; ///< synthetic with images: false replays the stored tracklets instead
  // A rig's files come from the command line only (not config keys: a configuration is
  // meant to be reused across inputs).
  std::string calib;      ///< a rig's calibration file (--calib; required for a plain folder)
  std::string gt;         ///< a rig's TUM-format ground truth (--gt)
  void Check() const;
  void Load(OptionsReader& r);
};

/// Recognises the kind of `path` and opens it. A KITTI raw drive with only the colour pair
/// (image_02/03) is read from it whatever options.color says (RunInput::color, and the log,
/// say so); one with neither complete pair is an InputError naming the four folders. Throws InputError naming the file and what
/// was expected when it is none of the known kinds or is malformed.
RunInput OpenRunInput(const std::string& path, const InputOptions& options);

/// A generated synthetic sequence as an input of replayed tracklets (no images), cut to its
/// first `max_frames` frames (0 = all) — what OpenRunInput gives for the same sequence on disk.
RunInput SyntheticRunInput(SyntheticSequence sequence, int max_frames = 0);

}  // namespace cslam
