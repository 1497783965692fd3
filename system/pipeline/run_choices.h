#pragma once
// The named choices of a run (`preset`, `method`, `mode` in YAML; --preset, --method, --mode on
// the command line). Each enum has one spelling table, used by the YAML reader, the command
// line's list of allowed values, the messages and the effective configuration, so the words
// are listed once. The ablation's table is next to its enum (backend/clusterslam.h).
#include "core/enum_names.h"

namespace cslam {

/// The backend parameter set of the paper's two kinds of scene (ε, chunk lengths).
enum class Preset { kIndoor, kOutdoor };
inline constexpr EnumName<Preset> kPresetNames[] = {
    {Preset::kIndoor, "indoor"},
    {Preset::kOutdoor, "outdoor"},
};

/// The backend that estimates each window (or the whole sequence).
enum class Method {
  kClusterSlam,  ///< this project's ClusterSLAM
  kFullBa,       ///< baseline: one static bundle adjustment
  kPdcs,         ///< baseline: Progressive DCS
  kTrueLabels,   ///< reference: the generator's labels (synthetic input without images)
};
inline constexpr EnumName<Method> kMethodNames[] = {
    {Method::kClusterSlam, "clusterslam"},
    {Method::kFullBa, "full-ba"},
    {Method::kPdcs, "pdcs"},
    {Method::kTrueLabels, "true-labels"},
};

/// Sliding windows while the sequence is read, or one solve over the whole sequence.
enum class RunMode { kOnline, kBatch };
inline constexpr EnumName<RunMode> kRunModeNames[] = {
    {RunMode::kOnline, "online"},
    {RunMode::kBatch, "batch"},
};

}  // namespace cslam
