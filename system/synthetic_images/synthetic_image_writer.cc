#include "system/synthetic_images/synthetic_image_writer.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <random>

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

// Adds uniform integer noise in [-n, n] to every pixel, saturating; the stream is fixed by
// (seed, frame, camera) so that any frame can be redrawn alone.
void AddGreyNoise(int n, uint64_t seed, int frame, int camera, cv::Mat* image) {
  std::mt19937_64 engine(seed * 1000003ULL + static_cast<uint64_t>(frame) * 2ULL + static_cast<uint64_t>(camera));
  const uint64_t span = 2ULL * static_cast<uint64_t>(n) + 1ULL;
  for (int y = 0; y < image->rows; ++y) {
    uint8_t* row = image->ptr<uint8_t>(y);
    for (int x = 0; x < image->cols; ++x) {
      const int v = row[x] + static_cast<int>(engine() % span) - n;
      row[x] = static_cast<uint8_t>(std::clamp(v, 0, 255));
    }
  }
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
    RenderedStereoFrame images = renderer.Render(sequence, f);
    if (options.grey_noise > 0) {
      AddGreyNoise(options.grey_noise, options.grey_noise_seed, f, 0, &images.left);
      AddGreyNoise(options.grey_noise, options.grey_noise_seed, f, 1, &images.right);
    }
    WritePng(images.left, (seq / "image_0" / SyntheticFrameFile(f)).string());
    WritePng(images.right, (seq / "image_1" / SyntheticFrameFile(f)).string());
    WritePng(images.object_id, (seq / "object_id" / SyntheticFrameFile(f)).string());
    if (progress) progress(f + 1, frames);
  }
}

}  // namespace cslam
