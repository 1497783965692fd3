#pragma once
// On-disk form of a synthetic sequence: a folder of small text files, described in
// docs/formats.md ("Synthetic sequence"). Numbers are written in their shortest exact decimal
// form, so Write followed by Read gives back identical values.
#include <string>

#include "system/synthetic/synthetic_scene.h"

namespace cslam {

/// Writes `sequence` into folder `dir` (created when missing), every file atomically.
/// Throws OutputError.
void WriteSynthetic(const SyntheticSequence& sequence, const std::string& dir);

/// Reads and validates a folder written by WriteSynthetic. Throws InputError(file, line, what)
/// on a missing file, a malformed or non-finite value, an unknown id, a count that disagrees
/// with sequence.txt, or an observation with non-positive disparity or whose ground-truth
/// point is not in front of the camera.
SyntheticSequence ReadSynthetic(const std::string& dir);

/// True when `dir` has the files of a synthetic sequence (cheap: names only, no parsing).
bool LooksLikeSynthetic(const std::string& dir);

}  // namespace cslam
