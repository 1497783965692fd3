// Fuzz target: one KITTI raw OXTS packet (oxts/data/*.txt) and its conversion to poses.
#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/datasets/oxts.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  cslam::fuzz::WriteInput(data, size, "oxts/data/0000000000.txt");
  try {
    const auto packets = cslam::ReadOxts((cslam::fuzz::ScratchDir() / "oxts").string());
    cslam::OxtsToCameraPoses(packets, cslam::Pose::Identity());
  } catch (const cslam::Error&) {
  }
  return 0;
}
