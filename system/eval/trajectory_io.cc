#include "system/eval/trajectory_io.h"

#include <Eigen/SVD>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

namespace {

// Files come from other tools that print 6-9 significant digits; anything further off than
// this is not a rotation.
constexpr double kRotationTolerance = 1e-3;

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  std::string field;
  while (in >> field) {
    fields.push_back(field);
  }
  return fields;
}

bool IsDataLine(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first != std::string::npos && line[first] != '#';
}

double ParseNumber(const std::string& text, const std::string& file, int line) {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') {
    ++begin;  // from_chars rejects the '+' printf may write
  }
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end) {
    throw InputError(file, line, "expected a number, got '" + text + "'");
  }
  if (!std::isfinite(value)) {
    throw InputError(file, line, "expected a finite number, got '" + text + "'");
  }
  return value;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

std::string FormatNumber(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, ptr);
}

// Calls `row(fields, line_number)` for each data line of `file`.
template <typename RowFn>
void ForEachDataLine(const std::string& file, RowFn row) {
  std::ifstream in(file);
  if (!in) {
    throw InputError(file, "cannot open the trajectory file");
  }
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!IsDataLine(line)) {
      continue;
    }
    row(SplitFields(line), line_number);
  }
  if (in.bad()) {
    throw InputError(file, "read error");
  }
}

// The frame indices of `file`, and the line of its last one in *last_line.
std::vector<int> ReadFrameIndexLines(const std::string& file, int* last_line) {
  std::vector<int> frames;
  ForEachDataLine(file, [&](const std::vector<std::string>& fields, int line) {
    if (last_line != nullptr) *last_line = line;
    if (fields.size() != 1) {
      throw InputError(file, line, "expected one frame index per line");
    }
    int frame = 0;
    const char* end = fields[0].data() + fields[0].size();
    const auto [ptr, err] = std::from_chars(fields[0].data(), end, frame);
    if (err != std::errc() || ptr != end || frame < 0) {
      throw InputError(file, line, "expected a non-negative integer frame index");
    }
    if (!frames.empty() && frame <= frames.back()) {
      throw InputError(file, line, "expected increasing frame indices");
    }
    frames.push_back(frame);
  });
  return frames;
}

void ReadFrameIndexFile(const std::string& file, Trajectory& trajectory) {
  const std::string index_file = FrameIndexPathFor(file);
  std::error_code ec;
  if (!std::filesystem::exists(index_file, ec)) {
    return;
  }
  int last_line = 0;
  std::vector<int> frames = ReadFrameIndexLines(index_file, &last_line);
  if (frames.size() != trajectory.size()) {
    throw InputError(index_file, last_line,
                     "expected " + std::to_string(trajectory.size()) +
                         " frame indices (one per pose of " + file + "), got " +
                         std::to_string(frames.size()));
  }
  trajectory.frames = std::move(frames);
}

}  // namespace

std::string FrameIndexPathFor(const std::string& file) {
  const std::filesystem::path p(file);
  return (p.parent_path() / (p.stem().string() + "_frames.txt")).string();
}

std::vector<int> ReadFrameIndices(const std::string& file) { return ReadFrameIndexLines(file, nullptr); }

const char* TrajectoryFormatName(TrajectoryFormat format) {
  return format == TrajectoryFormat::kKitti ? "kitti" : "tum";
}

Trajectory ReadTrajectory(const std::string& file, TrajectoryFormat format) {
  Trajectory trajectory;
  if (format == TrajectoryFormat::kKitti) {
    ForEachDataLine(file, [&](const std::vector<std::string>& fields, int line) {
      if (fields.size() != 12) {
        throw InputError(file, line,
                         "expected 12 numbers (row-major 3x4 pose, KITTI format), got " +
                             std::to_string(fields.size()) + " fields");
      }
      Eigen::Matrix<double, 3, 4> m;
      for (int k = 0; k < 12; ++k) {
        m(k / 4, k % 4) = ParseNumber(fields[k], file, line);
      }
      const Eigen::Matrix3d r = m.leftCols<3>();
      const double off = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
      if (off > kRotationTolerance || r.determinant() <= 0) {
        throw InputError(file, line,
                         "expected an orthonormal rotation with determinant +1 (|R^T R - I| = " +
                             FormatNumber(off) + ")");
      }
      Pose pose = Pose::Identity();
      pose.linear() = NearestRotation(r);
      pose.translation() = m.col(3);
      trajectory.frames.push_back(int(trajectory.poses.size()));
      trajectory.poses.push_back(pose);
    });
    ReadFrameIndexFile(file, trajectory);
  } else {
    ForEachDataLine(file, [&](const std::vector<std::string>& fields, int line) {
      if (fields.size() != 8) {
        throw InputError(file, line,
                         "expected 8 fields 't x y z qx qy qz qw' (TUM format), got " +
                             std::to_string(fields.size()));
      }
      double v[8];
      for (int k = 0; k < 8; ++k) {
        v[k] = ParseNumber(fields[k], file, line);
      }
      if (!trajectory.timestamps.empty() && v[0] < trajectory.timestamps.back()) {
        throw InputError(file, line, "expected non-decreasing timestamps");
      }
      Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      if (std::abs(q.norm() - 1.0) > kRotationTolerance) {
        throw InputError(file, line,
                         "expected a unit quaternion (norm " + FormatNumber(q.norm()) + ")");
      }
      q.normalize();
      Pose pose = Pose::Identity();
      pose.linear() = q.toRotationMatrix();
      pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
      trajectory.timestamps.push_back(v[0]);
      trajectory.poses.push_back(pose);
    });
  }
  return trajectory;
}

void WriteTrajectory(const Trajectory& trajectory, const std::string& file,
                     TrajectoryFormat format) {
  CSLAM_CHECK(trajectory.timestamps.empty() || trajectory.timestamps.size() == trajectory.size(),
              "Trajectory timestamps must be empty or one per pose");
  CSLAM_CHECK(trajectory.frames.empty() || trajectory.frames.size() == trajectory.size(),
              "Trajectory frames must be empty or one per pose");
  if (format == TrajectoryFormat::kKitti) {
    WriteFileAtomically(file, [&](std::ostream& out) {
      for (const Pose& pose : trajectory.poses) {
        const Eigen::Matrix<double, 3, 4> m = pose.matrix().topRows<3>();
        for (int k = 0; k < 12; ++k) {
          out << (k ? " " : "") << FormatNumber(m(k / 4, k % 4));
        }
        out << '\n';
      }
    });
    bool contiguous = true;
    for (size_t i = 0; i < trajectory.frames.size(); ++i) {
      contiguous &= trajectory.frames[i] == int(i);
    }
    if (!contiguous) {
      WriteFileAtomically(FrameIndexPathFor(file), [&](std::ostream& out) {
        for (int frame : trajectory.frames) {
          out << frame << '\n';
        }
      });
    } else {
      // A stale index file from an earlier write would otherwise renumber this trajectory.
      std::error_code ec;
      std::filesystem::remove(FrameIndexPathFor(file), ec);
      if (ec)
        throw OutputError(FrameIndexPathFor(file),
                          "cannot remove the stale frame index: " + ec.message());
    }
    return;
  }
  WriteFileAtomically(file, [&](std::ostream& out) {
    for (size_t i = 0; i < trajectory.size(); ++i) {
      const Pose& pose = trajectory.poses[i];
      const double t = trajectory.HasTimestamps() ? trajectory.timestamps[i]
                       : trajectory.HasFrames()   ? double(trajectory.frames[i])
                                                  : double(i);
      const Eigen::Quaterniond q(pose.linear());
      const Eigen::Vector3d p = pose.translation();
      out << FormatNumber(t) << ' ' << FormatNumber(p.x()) << ' ' << FormatNumber(p.y()) << ' '
          << FormatNumber(p.z()) << ' ' << FormatNumber(q.x()) << ' ' << FormatNumber(q.y()) << ' '
          << FormatNumber(q.z()) << ' ' << FormatNumber(q.w()) << '\n';
    }
  });
}

TrajectoryFormat GuessTrajectoryFormat(const std::string& file) {
  // The first data line decides; the rest of the file is read by whoever loads it.
  std::optional<TrajectoryFormat> format;
  ForEachDataLine(file, [&](const std::vector<std::string>& fields, int line) {
    if (format) return;
    if (fields.size() == 12) {
      format = TrajectoryFormat::kKitti;
    } else if (fields.size() == 8) {
      format = TrajectoryFormat::kTum;
    } else {
      throw InputError(file, line,
                       "expected 12 fields (KITTI) or 8 fields (TUM), got " +
                           std::to_string(fields.size()));
    }
  });
  if (!format) throw InputError(file, "expected at least one pose line, the file has none");
  return *format;
}

}  // namespace cslam
