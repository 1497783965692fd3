#include "system/datasets/asl_layout.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/rig_calibration.h"
#include "system/datasets/stereo_pair_files.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// data.csv: "timestamp_ns,filename" rows, '#' header; each image must exist under data/.
std::map<long long, std::string> ReadImageList(const fs::path& cam_dir) {
  const std::string csv = (cam_dir / "data.csv").string();
  std::ifstream in = OpenTextFile(csv, "image list data.csv (#timestamp [ns],filename)");
  std::map<long long, std::string> images;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const size_t comma = line.find(',');
    if (comma == std::string::npos)
      throw InputError(csv, line_no, "expected 'timestamp_ns,filename', got '" + line + "'");
    long long t = 0;
    std::string stamp = line.substr(first, comma - first);
    try {
      size_t used = 0;
      t = std::stoll(stamp, &used);
      if (used != stamp.size()) throw std::invalid_argument(stamp);
    } catch (const std::exception&) {
      throw InputError(csv, line_no, "expected an integer timestamp in nanoseconds, got '" + stamp + "'");
    }
    std::string name = line.substr(comma + 1);
    name.erase(0, name.find_first_not_of(" \t"));
    const fs::path file = cam_dir / "data" / name;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      throw InputError(csv, line_no, "names the image " + file.string() + ", which is missing");
    if (!images.emplace(t, file.string()).second)
      throw InputError(csv, line_no, "timestamp " + stamp + " given twice");
  }
  if (images.empty()) throw InputError(csv, "expected one row per image; the list has none");
  return images;
}

std::string Unpaired(const std::vector<long long>& stamps) {
  std::ostringstream s;
  for (size_t i = 0; i < stamps.size() && i < 5; ++i) s << (i ? ", " : "") << stamps[i];
  if (stamps.size() > 5) s << ", ...";
  return s.str();
}

}  // namespace

std::string AslCameraFolder(const std::string& path) {
  std::error_code ec;
  for (const fs::path& p : {fs::path(path) / "mav0", fs::path(path)})
    if (fs::is_directory(p / "cam0", ec) && fs::is_directory(p / "cam1", ec)) return p.string();
  return "";
}

std::unique_ptr<RigStereoSource> OpenAslSequence(const std::string& path, const std::string& calib,
                                                 const std::string& gt) {
  const std::string mav = AslCameraFolder(path);
  if (mav.empty()) throw InputError(path, "expected an ASL sequence: mav0/cam0 and mav0/cam1");
  const fs::path cam0 = fs::path(mav) / "cam0", cam1 = fs::path(mav) / "cam1";
  std::error_code ec;
  StereoRig rig;
  if (!calib.empty()) {
    rig = ReadRigCalibration(calib);
  } else {
    for (const fs::path& c : {cam0, cam1})
      if (!fs::is_regular_file(c / "sensor.yaml", ec))
        throw InputError((c / "sensor.yaml").string(),
                         "missing: expected the camera's calibration (EuRoC sensor.yaml), or give "
                         "one for both cameras with --calib FILE");
    rig = ReadEurocSensorPair((cam0 / "sensor.yaml").string(), (cam1 / "sensor.yaml").string());
  }

  const std::map<long long, std::string> left = ReadImageList(cam0), right = ReadImageList(cam1);
  RigFrames frames;
  std::vector<long long> left_only, right_only;
  const long long t0 = left.begin()->first < right.begin()->first ? left.begin()->first : right.begin()->first;
  for (const auto& [t, file] : left) {
    const auto it = right.find(t);
    if (it == right.end()) {
      left_only.push_back(t);
      continue;
    }
    frames.left_files.push_back(file);
    frames.right_files.push_back(it->second);
    // Differences in integers first: seconds since the epoch in a double keep only ~0.2 µs.
    frames.times_s.push_back(static_cast<double>(t - t0) * 1e-9);
  }
  for (const auto& [t, file] : right)
    if (!left.count(t)) right_only.push_back(t);
  const std::string name = fs::path(NormalizedFolder(path)).filename().string();
  if (frames.left_files.empty())
    throw InputError((cam1 / "data.csv").string(),
                     "no timestamp of cam1 equals one of cam0 (" + (cam0 / "data.csv").string() +
                         "); expected synchronised cameras");
  if (!left_only.empty() || !right_only.empty())
    GetLogger("system")->warn("{}: {} cam0 frames without a cam1 partner ({}) and {} cam1 frames without "
                              "a cam0 partner ({}) are skipped; {} pairs remain",
                              name, left_only.size(), Unpaired(left_only), right_only.size(),
                              Unpaired(right_only), frames.left_files.size());

  std::optional<TimedPoses> truth;
  const double offset_s = static_cast<double>(t0) * 1e-9;
  if (!gt.empty()) {
    truth = ReadTumPoses(gt);
  } else {
    for (const char* f : {"state_groundtruth_estimate0/data.csv", "mocap0/data.csv"}) {
      const fs::path file = fs::path(mav) / f;
      if (fs::is_regular_file(file, ec)) {
        truth = ReadAslPoses(file.string());
        break;
      }
    }
  }
  // Image times above are relative to t0; bring the ground truth to the same clock.
  if (truth)
    for (double& t : truth->times) t -= offset_s;
  return std::make_unique<RigStereoSource>(name, "euroc", std::move(rig), std::move(frames), std::move(truth));
}

}  // namespace cslam
