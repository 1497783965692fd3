#include "system/synthetic_images/synthetic_image_writer.h"

#include <charconv>
#include <filesystem>

#include "core/atomic_file.h"
#include "system/io/image_io.h"
#include "system/synthetic/synthetic_image_io.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

std::string Num(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

}  // namespace

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
  WriteFileAtomically(SyntheticPosesFile(dir), [&](std::ostream& out) {
    for (const Pose& p : sequence.world_from_cam)
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 4; ++k) out << Num(p.matrix()(r, k)) << (r == 2 && k == 3 ? '\n' : ' ');
  });

  SyntheticRenderer renderer(sequence.geometry, sequence.camera, options);
  const int frames = sequence.num_frames();
  for (int f = 0; f < frames; ++f) {
    const RenderedStereoFrame images = renderer.Render(sequence, f);
    WritePng(images.left, (seq / "image_0" / SyntheticFrameFile(f)).string());
    WritePng(images.right, (seq / "image_1" / SyntheticFrameFile(f)).string());
    WritePng(images.object_id, (seq / "object_id" / SyntheticFrameFile(f)).string());
    if (progress) progress(f + 1, frames);
  }
}

}  // namespace cslam
