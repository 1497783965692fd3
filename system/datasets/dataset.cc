#include "system/datasets/dataset.h"

#include <filesystem>

#include "core/errors.h"
#include "system/datasets/asl_layout.h"
#include "system/datasets/stereo_folder.h"
#include "system/datasets/kitti_odometry_reader.h"
#include "system/datasets/kitti_raw_reader.h"

namespace cslam {

namespace fs = std::filesystem;

DatasetKind DetectDataset(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (!fs::is_directory(p, ec)) return DatasetKind::kUnknown;
  if (fs::is_directory(p / "image_00", ec) || fs::is_directory(p / "image_02", ec))
    return DatasetKind::kKittiRaw;
  if (fs::is_directory(p / "image_0", ec) && fs::exists(p / "calib.txt", ec))
    return DatasetKind::kKittiOdometry;
  if (fs::is_regular_file(p / "observations.csv", ec)) return DatasetKind::kSynthetic;
  if (!AslCameraFolder(path).empty()) return DatasetKind::kAsl;
  if (fs::is_directory(p / "left", ec) && fs::is_directory(p / "right", ec)) return DatasetKind::kStereoFolder;
  return DatasetKind::kUnknown;
}

std::unique_ptr<StereoSource> OpenStereoSource(const std::string& path, const StereoSourceOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "expected a dataset folder; it does not exist");
  if (!fs::is_directory(path, ec)) throw InputError(path, "expected a dataset folder; it is a file");
  const DatasetKind kind = DetectDataset(path);
  if ((kind == DatasetKind::kKittiRaw || kind == DatasetKind::kKittiOdometry) &&
      (!options.calib.empty() || !options.gt.empty()))
    throw InputError(path, "is a KITTI folder, which carries its own calibration and ground truth; "
                           "expected no --calib or --gt (they are for an ASL sequence or a plain "
                           "left/ right/ folder)");
  switch (kind) {
    case DatasetKind::kKittiRaw:
      return std::make_unique<KittiRawSource>(path, options.color);
    case DatasetKind::kKittiOdometry:
      return std::make_unique<KittiOdometrySource>(path);
    case DatasetKind::kSynthetic:
      throw InputError(path, "is a synthetic sequence (observations file): it has no stereo "
                             "images; open it with the synthetic reader");
    case DatasetKind::kAsl:
      return OpenAslSequence(path, options.calib, options.gt);
    case DatasetKind::kStereoFolder:
      return OpenStereoFolder(path, options.calib, options.gt);
    case DatasetKind::kUnknown:
      break;
  }
  // The likely mistake behind an odometry-looking folder is a missing calib.txt: say so.
  const std::string hint = fs::is_directory(fs::path(path) / "image_0", ec)
                               ? " (it has image_0/ but no calib.txt)"
                               : "";
  throw InputError(path,
                   "is none of the known kinds: expected a KITTI raw drive folder (image_00/…), "
                   "a KITTI odometry sequence (image_0/…, calib.txt), an ASL/EuRoC sequence "
                   "(mav0/cam0, mav0/cam1), a plain stereo folder (left/, right/) or a synthetic "
                   "sequence (observations file)" + hint);
}

}  // namespace cslam
