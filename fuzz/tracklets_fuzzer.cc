// Fuzz target: KITTI raw tracklet_labels.xml (the XML tree reader and the label reader).
#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/datasets/kitti_tracklets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cslam::fuzz::WriteInput(data, size, "tracklet_labels.xml");
  try {
    cslam::ReadTrackletLabels(path, cslam::Pose::Identity(), 20);
  } catch (const cslam::Error&) {
  }
  return 0;
}
