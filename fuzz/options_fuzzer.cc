// Fuzz target: a YAML configuration through the same path as `cslam run --config`
// (OptionsReader → PipelineOptions::Load → Check), then the effective-configuration dump.
#include "core/errors.h"
#include "fuzz/fuzz_support.h"
#include "system/pipeline/pipeline_options.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cslam::fuzz::WriteInput(data, size, "config.yaml");
  try {
    const cslam::PipelineOptions o = cslam::LoadPipelineOptions(cslam::Preset::kOutdoor, path);
    o.ToYaml();
  } catch (const cslam::Error&) {
  }
  return 0;
}
