#pragma once
// Paths of the shared KITTI data and builders of small, editable copies of it in a temporary
// folder (images symlinked, text files copied) for the bad-input tests.
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

namespace cslam::testing {

namespace fs = std::filesystem;

/// The shared data folder: the compile-time CSLAM_SHARED_DATA_DIR when it exists, else
/// $CSLAM_SHARED_DATA (a git worktree's compile-time path points beside the worktree).
inline fs::path SharedData() {
  if (fs::is_directory(CSLAM_SHARED_DATA_DIR)) return CSLAM_SHARED_DATA_DIR;
  if (const char* env = std::getenv("CSLAM_SHARED_DATA"); env && fs::is_directory(env)) return env;
  return CSLAM_SHARED_DATA_DIR;
}
inline fs::path RawDateDir() { return SharedData() / "kitti_raw" / "2011_09_26"; }
inline fs::path RawDriveDir() { return RawDateDir() / "2011_09_26_drive_0005_sync"; }
inline fs::path OdometrySequenceDir() { return SharedData() / "kitti_odometry" / "sequences" / "clip_a"; }

/// The whole file; throws when it cannot be read so a missing data folder fails the test.
inline std::string ReadText(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw std::runtime_error("test data not found: " + p.string() + " (set CSLAM_SHARED_DATA)");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void WriteText(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  fs::remove(p);  // may be a symlink into the read-only data
  std::ofstream(p) << text;
}

inline std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream s(text);
  for (std::string l; std::getline(s, l);) lines.push_back(l);
  return lines;
}

inline std::string JoinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

/// 1-based line of the first line starting with `prefix` in `file`, 0 when none.
inline int LineStartingWith(const fs::path& file, const std::string& prefix) {
  const auto lines = Lines(ReadText(file));
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines[i].rfind(prefix, 0) == 0) return static_cast<int>(i) + 1;
  return 0;
}

/// Replaces the line starting with `prefix` by `replacement` (the whole line).
inline void ReplaceLine(const fs::path& file, const std::string& prefix, const std::string& replacement) {
  auto lines = Lines(ReadText(file));
  for (auto& l : lines)
    if (l.rfind(prefix, 0) == 0) l = replacement;
  WriteText(file, JoinLines(lines));
}

/// A fresh, empty temporary folder unique to this process and `tag`; removed by the destructor.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(fs::temp_directory_path() / ("cslam_" + tag + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Copies the first `frames` frames of drive 0005 into `root`/2011_09_26/<drive>: images as
/// symlinks, timestamps/oxts/calibration as editable copies; tracklets only when asked (they
/// cover 154 frames). Returns the drive folder.
inline fs::path MakeRawCopy(const fs::path& root, int frames, bool with_oxts = true) {
  const fs::path date = root / "2011_09_26";
  const fs::path drive = date / "2011_09_26_drive_0005_sync";
  for (const char* f : {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"})
    WriteText(date / f, ReadText(RawDateDir() / f));
  for (const char* cam : {"image_00", "image_01"}) {
    fs::create_directories(drive / cam / "data");
    const auto stamps = Lines(ReadText(RawDriveDir() / cam / "timestamps.txt"));
    WriteText(drive / cam / "timestamps.txt",
              JoinLines(std::vector<std::string>(stamps.begin(), stamps.begin() + frames)));
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.png", i);
      fs::create_symlink(RawDriveDir() / cam / "data" / name, drive / cam / "data" / name);
    }
  }
  if (with_oxts) {
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.txt", i);
      WriteText(drive / "oxts" / "data" / name, ReadText(RawDriveDir() / "oxts" / "data" / name));
    }
  }
  return drive;
}

/// Copies the first `frames` frames of the odometry clip into `root`/sequences/clip_a (images
/// symlinked) with calib.txt, times.txt and poses/clip_a.txt. Returns the sequence folder.
inline fs::path MakeOdometryCopy(const fs::path& root, int frames) {
  const fs::path seq = root / "sequences" / "clip_a";
  WriteText(seq / "calib.txt", ReadText(OdometrySequenceDir() / "calib.txt"));
  const auto times = Lines(ReadText(OdometrySequenceDir() / "times.txt"));
  WriteText(seq / "times.txt", JoinLines(std::vector<std::string>(times.begin(), times.begin() + frames)));
  const auto poses = Lines(ReadText(SharedData() / "kitti_odometry" / "poses" / "clip_a.txt"));
  WriteText(root / "poses" / "clip_a.txt",
            JoinLines(std::vector<std::string>(poses.begin(), poses.begin() + frames)));
  for (const char* cam : {"image_0", "image_1"}) {
    fs::create_directories(seq / cam);
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.png", i);
      fs::create_symlink(OdometrySequenceDir() / cam / name, seq / cam / name);
    }
  }
  return seq;
}

}  // namespace cslam::testing

#include "core/errors.h"

namespace cslam::testing {

/// The message of the InputError `f` throws, or "<no InputError>" (other exceptions propagate
/// and fail the test).
template <typename F>
std::string InputErrorMessage(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "<no InputError>";
}

}  // namespace cslam::testing
