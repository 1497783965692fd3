#pragma once
// Reading and writing trajectory files in the KITTI and TUM formats (docs/formats.md).
#include <string>

#include "system/eval/trajectory.h"

namespace cslam {

/// KITTI: 12 numbers per line, row-major 3x4 world_from_cam, line k (blank and '#' lines
/// skipped) is frame k. TUM: "t x y z qx qy qz qw".
enum class TrajectoryFormat { kKitti, kTum };

/// Reads a trajectory. KITTI gives `frames` (0, 1, ... or the side index file, see
/// FrameIndexPathFor) and no timestamps; TUM gives `timestamps` (non-decreasing) and no
/// frames. Fields may be separated by any whitespace; blank lines and lines starting with '#'
/// are skipped. Rotations must be orthonormal within 1e-3 (KITTI) or have a unit quaternion
/// within 1e-3 (TUM); they are projected onto SO(3) exactly. Throws InputError(file, line,
/// expected) on a wrong field count, an unparsable or non-finite number, a bad rotation or
/// decreasing timestamps, and InputError(file) when the file cannot be opened.
Trajectory ReadTrajectory(const std::string& file, TrajectoryFormat format);

/// Writes atomically (WriteFileAtomically). Numbers use the shortest text that reads back to
/// the same double. TUM: "t x y z qx qy qz qw" separated by single spaces, the timestamp being
/// the frame index when the trajectory has no timestamps. KITTI: 12 numbers row-major 3x4;
/// when the frames are not exactly 0, 1, ..., n-1 the frame indices are also written, one per
/// line, to FrameIndexPathFor(file) so that ReadTrajectory restores them (otherwise an old
/// index file there is removed).
void WriteTrajectory(const Trajectory& trajectory, const std::string& file,
                     TrajectoryFormat format);

/// Side file holding the frame index of each line of a KITTI trajectory: "<stem>_frames.txt"
/// beside it ("objects/3.txt" → "objects/3_frames.txt"); '#' lines in it are comments.
std::string FrameIndexPathFor(const std::string& file);

/// Reads a frame index list (such a side file, or a list given beside another system's
/// trajectory): one non-negative, increasing integer per data line. Throws InputError naming
/// the file and line.
std::vector<int> ReadFrameIndices(const std::string& file);

/// KITTI when the first data line has 12 fields, TUM when it has 8; otherwise throws
/// InputError naming the line.
TrajectoryFormat GuessTrajectoryFormat(const std::string& file);

/// "kitti" / "tum".
const char* TrajectoryFormatName(TrajectoryFormat format);

}  // namespace cslam
