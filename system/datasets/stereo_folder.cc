#include "system/datasets/stereo_folder.h"

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/rig_calibration.h"
#include "system/datasets/stereo_pair_files.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

std::unique_ptr<RigStereoSource> OpenStereoFolder(const std::string& path, const std::string& calib,
                                                  const std::string& gt) {
  const fs::path dir = NormalizedFolder(path);
  if (calib.empty())
    throw InputError(path, "is a plain stereo folder (left/, right/): expected its calibration with "
                           "--calib FILE (Kalibr camchain, OpenCV stereo calibration or ORB-SLAM3 "
                           "settings; docs/own_rig.md)");
  StereoRig rig = ReadRigCalibration(calib);
  RigFrames frames;
  ListStereoPairs((dir / "left").string(), (dir / "right").string(), &frames.left_files, &frames.right_files);
  const fs::path times = dir / "times.txt";
  std::error_code ec;
  if (fs::exists(times, ec)) {
    frames.times_s = ReadSecondsTimestamps(times.string());
    // Those start at 0; a ground truth is on the file's own clock, so add its first time back.
    std::ifstream in = OpenTextFile(times.string(), "times file");
    std::string line;
    int line_no = 0;
    while (std::getline(in, line) && ++line_no)
      if (line.find_first_not_of(" \t\r") != std::string::npos) {
        const double first = ParseNumbers(line, times.string(), line_no).at(0);
        for (double& t : frames.times_s) t += first;
        break;
      }
    if (frames.times_s.size() != frames.left_files.size())
      throw InputError(times.string(), "expected one time per image pair (" +
                                           std::to_string(frames.left_files.size()) + "), got " +
                                           std::to_string(frames.times_s.size()));
  } else {
    GetLogger("system")->warn("{}: no times.txt; the pairs are taken as 0.1 s apart", path);
    for (size_t i = 0; i < frames.left_files.size(); ++i) frames.times_s.push_back(0.1 * static_cast<double>(i));
  }
  std::optional<TimedPoses> truth;
  if (!gt.empty()) truth = ReadTumPoses(gt);
  return std::make_unique<RigStereoSource>(dir.filename().string(), "stereo_folder", std::move(rig),
                                           std::move(frames), std::move(truth));
}

}  // namespace cslam
