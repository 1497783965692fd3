#include "system/datasets/calibration_yaml.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

CalibrationYaml CalibrationYaml::Read(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "calibration file");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    // OpenCV writes "%YAML:1.0", a directive YAML 1.2 parsers refuse; an empty line in its
    // place keeps every later line number right.
    if (first && line.rfind("%YAML", 0) == 0) line.clear();
    first = false;
    text << line << '\n';
  }
  CalibrationYaml y;
  y.path_ = path;
  try {
    y.root_ = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.is_null() ? 0 : e.mark.line + 1, "not valid YAML: " + e.msg);
  }
  if (!y.root_.IsMap()) throw InputError(path, "expected a YAML map of calibration keys");
  return y;
}

void CalibrationYaml::Fail(const YAML::Node& node, const std::string& key, const std::string& what) const {
  const int line = node && !node.Mark().is_null() ? node.Mark().line + 1 : 0;
  throw InputError(path_, line, "'" + key + "': " + what);
}

bool CalibrationYaml::Has(const YAML::Node& parent, const std::string& key) {
  return parent.IsMap() && parent[key].IsDefined() && !parent[key].IsNull();
}

namespace {

const YAML::Node Child(const CalibrationYaml& y, const YAML::Node& parent, const std::string& key) {
  if (!CalibrationYaml::Has(parent, key)) y.Fail(parent, key, "missing; expected it in this calibration file");
  return parent[key];
}

double ScalarNumber(const CalibrationYaml& y, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) y.Fail(node, key, "expected a number");
  const std::string s = node.Scalar();
  try {
    size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  y.Fail(node, key, "expected a finite number, got '" + s + "'");
}

// A count or size read as a double, printed without converting it to int (out of range: UB).
std::string Count(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

}  // namespace

YAML::Node CalibrationYaml::Map(const YAML::Node& parent, const std::string& key) const {
  YAML::Node n = Child(*this, parent, key);
  if (!n.IsMap()) Fail(n, key, "expected a map of keys");
  return n;
}

double CalibrationYaml::Number(const YAML::Node& parent, const std::string& key) const {
  return ScalarNumber(*this, Child(*this, parent, key), key);
}

std::string CalibrationYaml::Text(const YAML::Node& parent, const std::string& key) const {
  const YAML::Node n = Child(*this, parent, key);
  if (!n.IsScalar()) Fail(n, key, "expected a word");
  return n.Scalar();
}

std::vector<double> CalibrationYaml::Numbers(const YAML::Node& parent, const std::string& key,
                                             int count) const {
  const YAML::Node n = Child(*this, parent, key);
  std::vector<double> v;
  YAML::Node list = n;
  if (n.IsMap()) {  // !!opencv-matrix, or EuRoC's {rows, cols, data}
    if (!Has(n, "data")) Fail(n, key, "expected a matrix with rows, cols and data");
    list = n["data"];
  }
  if (!list.IsSequence()) Fail(n, key, "expected a list of numbers");
  for (const YAML::Node& item : list) {
    if (item.IsSequence()) {  // a list of rows
      for (const YAML::Node& x : item) v.push_back(ScalarNumber(*this, x, key));
    } else {
      v.push_back(ScalarNumber(*this, item, key));
    }
  }
  if (n.IsMap()) {
    const double rows = Number(n, "rows"), cols = Number(n, "cols");
    if (rows * cols != static_cast<double>(v.size()))
      Fail(n, key, "expected rows x cols = " + Count(rows * cols) +
                       " numbers in data, got " + std::to_string(v.size()));
  }
  if (count >= 0 && static_cast<int>(v.size()) != count)
    Fail(n, key, "expected " + std::to_string(count) + " numbers, got " + std::to_string(v.size()));
  return v;
}

Eigen::MatrixXd CalibrationYaml::Matrix(const YAML::Node& parent, const std::string& key, int rows,
                                        int cols) const {
  const YAML::Node n = Child(*this, parent, key);
  if (n.IsMap() && Has(n, "rows") && Has(n, "cols")) {
    const double r = Number(n, "rows"), c = Number(n, "cols");
    if (r != rows || c != cols)
      Fail(n, key, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got " +
                       Count(r) + "x" + Count(c));
  }
  const std::vector<double> v = Numbers(parent, key, rows * cols);
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = v[static_cast<size_t>(i * cols + j)];
  return m;
}

}  // namespace cslam
