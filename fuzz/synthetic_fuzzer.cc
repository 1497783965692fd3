// Fuzz target: the synthetic sequence reader. A small valid sequence is written once; the
// first input byte picks which of its files the rest of the input replaces (observations.csv
// most often), so every file's parser is reached from a mostly valid folder.
#include <array>
#include <map>

#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"

namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 9> kFiles = {"observations.csv", "sequence.txt",     "camera.txt",
                                               "times.txt",        "gt_camera.txt",    "gt_landmarks.csv",
                                               "gt_geometry.csv",  "gt_objects/0.txt", "gt_objects/1.txt"};

// The pristine files of a 3-frame sequence, by name (what `cslam synth --preset indoor --seed 1
// --frames 3 --objects 1 --landmark-density 0.05` writes; the seed corpus is made from it).
const std::map<std::string, std::string>& Pristine() {
  static const std::map<std::string, std::string> files = [] {
    cslam::SyntheticOptions o;
    o.preset = "indoor";
    o.seed = 1;
    o.frames = 3;
    o.objects = 1;
    o.landmark_density = 0.05;
    const fs::path dir = cslam::fuzz::ScratchDir() / "pristine";
    cslam::WriteSynthetic(cslam::GenerateSynthetic(o), dir.string());
    std::map<std::string, std::string> m;
    for (const char* f : kFiles) {
      std::ifstream in(dir / f, std::ios::binary);
      m[f] = std::string(std::istreambuf_iterator<char>(in), {});
    }
    return m;
  }();
  return files;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string target = kFiles[data[0] % kFiles.size()];
  for (const auto& [name, text] : Pristine()) {
    const std::string& content = name == target ? std::string(reinterpret_cast<const char*>(data + 1), size - 1) : text;
    cslam::fuzz::WriteInput(reinterpret_cast<const uint8_t*>(content.data()), content.size(), "seq/" + name);
  }
  try {
    cslam::ReadSynthetic((cslam::fuzz::ScratchDir() / "seq").string());
  } catch (const cslam::Error&) {
  }
  return 0;
}
