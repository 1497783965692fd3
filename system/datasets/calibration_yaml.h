#pragma once
// A calibration file read as YAML the way users have them: OpenCV's FileStorage output starts
// with "%YAML:1.0" (which YAML parsers reject) and stores matrices as !!opencv-matrix maps.
// Every accessor names the file, the line and the key when a value is missing or malformed.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cslam {

/// A parsed calibration YAML file and typed access to its keys.
class CalibrationYaml {
 public:
  /// Reads and parses `path`. Throws InputError naming the file (and line) when it cannot be
  /// read or is not YAML. A first line "%YAML:1.0" is skipped (line numbers are kept).
  static CalibrationYaml Read(const std::string& path);

  const std::string& path() const { return path_; }
  const YAML::Node& root() const { return root_; }
  /// The map under `key` of `parent` (root() for top-level keys). Throws when missing or not a map.
  YAML::Node Map(const YAML::Node& parent, const std::string& key) const;
  /// Whether `parent` has `key`.
  static bool Has(const YAML::Node& parent, const std::string& key);

  double Number(const YAML::Node& parent, const std::string& key) const;
  std::string Text(const YAML::Node& parent, const std::string& key) const;
  /// A flat list of numbers; `count` < 0 accepts any length, else exactly `count`. An
  /// !!opencv-matrix (or any map with rows, cols, data) is accepted and flattened row-major.
  std::vector<double> Numbers(const YAML::Node& parent, const std::string& key, int count = -1) const;
  /// A rows×cols matrix from a flat list, a list of rows or an !!opencv-matrix map.
  Eigen::MatrixXd Matrix(const YAML::Node& parent, const std::string& key, int rows, int cols) const;

  /// Throws InputError(path, line of `node`, "'key': what").
  [[noreturn]] void Fail(const YAML::Node& node, const std::string& key, const std::string& what) const;

 private:
  std::string path_;
  YAML::Node root_;
};

}  // namespace cslam
