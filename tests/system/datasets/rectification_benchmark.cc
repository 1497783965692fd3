// The cost of rectification on a real 752x480 pair (EuRoC V1_01, radial-tangential): per frame
// (both images remapped) and once per run (the maps built). docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>

#include "system/datasets/asl_layout.h"
#include "system/datasets/rig_calibration.h"
#include "system/datasets/stereo_rectifier.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

fs::path Euroc() {
  const char* env = std::getenv("CSLAM_SHARED_DATA");
  return fs::path(env ? env : CSLAM_SHARED_DATA_DIR) / "euroc" / "V1_01_easy_first50";
}

StereoRig EurocRig() {
  return ReadEurocSensorPair((Euroc() / "mav0/cam0/sensor.yaml").string(), (Euroc() / "mav0/cam1/sensor.yaml").string());
}

void BM_RectifyPair752x480(benchmark::State& state) {
  const auto source = OpenAslSequence(Euroc().string(), "", "");
  const StereoFrame raw = source->LoadRaw(0);
  cv::Mat left, right;
  for (auto _ : state) {
    source->rectifier().Rectify(raw.left, raw.right, &left, &right);
    benchmark::DoNotOptimize(left.data);
  }
}
BENCHMARK(BM_RectifyPair752x480)->Unit(benchmark::kMillisecond);

void BM_BuildRectifier752x480(benchmark::State& state) {
  const StereoRig rig = EurocRig();
  for (auto _ : state) {
    StereoRectifier r(rig);
    benchmark::DoNotOptimize(r.camera().fx);
  }
}
BENCHMARK(BM_BuildRectifier752x480)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cslam
