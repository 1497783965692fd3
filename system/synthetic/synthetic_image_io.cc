#include "system/synthetic/synthetic_image_io.h"

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/io/image_io.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSequenceSubdir = "sequences/00";
constexpr const char* kPosesFile = "poses/00.txt";

std::string Num(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

std::string FrameFile(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return name;
}

}  // namespace

std::string SyntheticImagesDir(const std::string& dir) {
  return (fs::path(dir) / kSequenceSubdir).string();
}

bool HasSyntheticImages(const std::string& dir) {
  std::error_code ec;
  const fs::path seq = SyntheticImagesDir(dir);
  return fs::is_directory(seq / "image_0", ec) && fs::is_regular_file(seq / "calib.txt", ec);
}

void WriteSyntheticImages(const SyntheticSequence& sequence, const std::string& dir,
                          const SyntheticRenderOptions& options,
                          const std::function<void(int, int)>& progress) {
  const fs::path seq = SyntheticImagesDir(dir);
  const StereoCamera& c = sequence.camera;
  WriteFileAtomically((seq / "calib.txt").string(), [&](std::ostream& out) {
    // KITTI's rectified projections: P1 = K [I | (-baseline, 0, 0)].
    auto line = [&](const char* key, double tx) {
      out << key << ": " << Num(c.fx) << " 0 " << Num(c.cx) << " " << Num(tx) << " 0 " << Num(c.fy)
          << " " << Num(c.cy) << " 0 0 0 1 0\n";
    };
    line("P0", 0.0);
    line("P1", -c.fx * c.baseline);
  });
  WriteFileAtomically((seq / "times.txt").string(), [&](std::ostream& out) {
    for (double t : sequence.timestamps) out << Num(t) << '\n';
  });
  WriteFileAtomically((fs::path(dir) / kPosesFile).string(), [&](std::ostream& out) {
    for (const Pose& p : sequence.world_from_cam)
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 4; ++k) out << Num(p.matrix()(r, k)) << (r == 2 && k == 3 ? '\n' : ' ');
  });

  SyntheticRenderer renderer(sequence.geometry, sequence.camera, options);
  const int frames = sequence.num_frames();
  for (int f = 0; f < frames; ++f) {
    const RenderedStereoFrame images = renderer.Render(sequence, f);
    WritePng(images.left, (seq / "image_0" / FrameFile(f)).string());
    WritePng(images.right, (seq / "image_1" / FrameFile(f)).string());
    WritePng(images.object_id, (seq / "object_id" / FrameFile(f)).string());
    if (progress) progress(f + 1, frames);
  }
}

cv::Mat ReadObjectIdImage(const std::string& dir, int frame) {
  const std::string path = (fs::path(SyntheticImagesDir(dir)) / "object_id" / FrameFile(frame)).string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path, "expected an object-id image; it does not exist");
  cv::Mat ids = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (ids.empty()) throw InputError(path, "cannot decode the object-id image (not a PNG?)");
  if (ids.type() != CV_16UC1)
    throw InputError(path, "expected a 16-bit single-channel object-id PNG");
  return ids;
}

}  // namespace cslam
