#pragma once
// A dataset as a sequence of rectified stereo pairs with optional ground truth. Readers
// (kitti_raw_reader.h, kitti_odometry_reader.h, rig_stereo_source.h for a user's raw rig)
// validate calibration, timestamps and file lists in their constructors and decode (and
// rectify) images lazily in Load().
#include <opencv2/core/mat.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"

namespace cslam {

/// One decoded stereo pair.
struct StereoFrame {
  int index = 0;           ///< frame number in the sequence, 0-based
  double timestamp = 0.0;  ///< seconds from the first frame
  cv::Mat left, right;     ///< 8-bit grey (CV_8UC1), same size as the camera's image
};

/// A labelled 3-D object box in one frame. Box frame: origin at the centre of the bottom
/// face, x along the length, y along the width, z up (KITTI velodyne convention).
struct ObjectBox {
  int track_id = 0;    ///< index of the object in the label file, stable over frames
  std::string type;    ///< "Car", "Van", "Pedestrian", "Cyclist", ...
  Pose cam_from_box = Pose::Identity();  ///< box frame → rectified left camera of this frame
  double h = 0, w = 0, l = 0;            ///< height (z), width (y), length (x), metres
};

/// A second estimate of the camera path from the ground-truth device itself, and the accuracy
/// the device states for its positions: what bounds any error measured against GroundTruth().
struct GroundTruthCrossCheck {
  std::string source;  ///< e.g. "OXTS velocities integrated"
  std::vector<Eigen::Vector3d> positions;  ///< per frame, in GroundTruth()'s world
  std::vector<double> position_accuracy_m; ///< per frame, as the device reports it (may be empty)
};

/// One sequence of rectified stereo pairs.
class StereoSource {
 public:
  virtual ~StereoSource() = default;
  /// Sequence name, e.g. "2011_09_26_drive_0005_sync" or "00".
  virtual std::string name() const = 0;
  /// "kitti_raw", "kitti_odometry", "euroc" (ASL layout) or "stereo_folder" (InputKind's names).
  virtual std::string kind() const = 0;
  virtual const StereoCamera& camera() const = 0;
  virtual int size() const = 0;
  /// Seconds from the first frame, strictly increasing, one per frame.
  virtual const std::vector<double>& timestamps() const = 0;
  /// Decodes frame `index` (0 <= index < size()). Throws InputError on a missing or corrupt
  /// image or a size mismatch. Thread-safe: const and without shared mutable state.
  virtual StereoFrame Load(int index) const = 0;
  /// world_from_cam per frame (world = rectified left camera at frame 0), when known.
  virtual std::optional<std::vector<Pose>> GroundTruth() const = 0;
  /// [frame] labelled object boxes; empty when the dataset has no labels.
  virtual std::vector<std::vector<ObjectBox>> ObjectBoxes() const { return {}; }
  /// The ground truth's cross-check, when the dataset has one (KITTI raw with OXTS).
  virtual std::optional<GroundTruthCrossCheck> CrossCheck() const { return std::nullopt; }
  /// Files (name, text) a run writes into its output folder to say how it understood the
  /// input, e.g. a user's rig: rig.yaml and rectified.yaml. Empty for the KITTI readers.
  virtual std::vector<std::pair<std::string, std::string>> DescriptionFiles() const { return {}; }
};

}  // namespace cslam
