#include "core/options_reader.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/errors.h"

namespace cslam {

OptionsReader::OptionsReader(YAML::Node node, std::string source, std::string path)
    : node_(std::move(node)), source_(std::move(source)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap())
    throw ConfigError(source_ + ": " + (path_.empty() ? "the document" : path_) +
                      " must be a mapping of key: value");
  // YAML parsers keep both entries of a repeated key and lookups see only the first, so a
  // second `online:` section (or key) would be ignored without a word.
  if (node_ && node_.IsMap()) {
    std::map<std::string, int> first_line;
    for (const auto& entry : node_) {
      if (!entry.first.IsScalar()) continue;
      const std::string key = entry.first.Scalar();
      const int line = entry.first.Mark().line + 1;
      const auto [it, fresh] = first_line.emplace(key, line);
      if (!fresh)
        throw ConfigError(source_ + ":" + std::to_string(line) + ": " +
                          PathOf(key) +
                          " given twice (first on line " + std::to_string(it->second) +
                          "); merge the two into one");
    }
  }
}

OptionsReader OptionsReader::FromFile(const std::string& file) {
  if (!std::filesystem::is_regular_file(file))
    throw ConfigError(file + ": config file not found");
  YAML::Node node;
  try {
    node = YAML::LoadFile(file);
  } catch (const YAML::Exception& e) {
    throw ConfigError(file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  return OptionsReader(node, file);
}

OptionsReader OptionsReader::FromString(const std::string& text, const std::string& source) {
  YAML::Node node;
  try {
    node = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  return OptionsReader(node, source);
}

OptionsReader OptionsReader::ForDump() {
  OptionsReader r(YAML::Node(YAML::NodeType::Map), "effective configuration");
  r.dumping_ = true;
  return r;
}

std::string OptionsReader::Dump() const {
  YAML::Emitter out;
  out << node_;
  return std::string(out.c_str()) + "\n";
}

std::string OptionsReader::PathOf(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

namespace {
// "file:12" or "file" when yaml-cpp has no position (nodes built in code, absent keys).
std::string AtLine(const std::string& source, int line) {
  return line > 0 ? source + ":" + std::to_string(line) : source;
}
}  // namespace

std::string OptionsReader::Where(const std::string& key) const {
  return AtLine(source_, LineOf(key)) + ": " + PathOf(key);
}

int OptionsReader::LineOf(const std::string& path) const {
  YAML::Node node = node_;
  std::string rest = path;
  while (node && node.IsMap()) {
    const std::size_t dot = rest.find('.');
    const std::string key = rest.substr(0, dot);
    YAML::Node next;
    int line = 0;
    for (const auto& entry : node) {
      if (entry.first.IsScalar() && entry.first.Scalar() == key) {
        next = entry.second;
        line = entry.first.Mark().line + 1;
        break;
      }
    }
    if (dot == std::string::npos || line == 0) return line;
    node = next;
    rest = rest.substr(dot + 1);
  }
  return 0;
}

bool OptionsReader::Has(const std::string& key) const {
  return node_ && node_.IsMap() && node_[key];
}

YAML::Node OptionsReader::Get(const std::string& key) {
  read_keys_.push_back(key);
  if (!Has(key)) return YAML::Node();
  return node_[key];
}

namespace {
template <typename T>
void ReadScalar(const YAML::Node& n, const std::string& where, const char* type, T* value) {
  if (!n.IsDefined() || n.IsNull()) return;
  if (!n.IsScalar()) throw ConfigError(where + ": expected " + type);
  try {
    *value = n.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where + ": expected " + type + ", got '" + n.Scalar() + "'");
  }
}
}  // namespace

void OptionsReader::Read(const std::string& key, double* value) {
  if (dumping_) {
    node_[key] = *value;
    return;
  }
  ReadScalar(Get(key), Where(key), "a number", value);
}
void OptionsReader::Read(const std::string& key, int* value) {
  if (dumping_) {
    node_[key] = *value;
    return;
  }
  ReadScalar(Get(key), Where(key), "an integer", value);
}
void OptionsReader::Read(const std::string& key, bool* value) {
  if (dumping_) {
    node_[key] = *value;
    return;
  }
  ReadScalar(Get(key), Where(key), "true or false", value);
}
void OptionsReader::Read(const std::string& key, std::string* value) {
  if (dumping_) {
    node_[key] = *value;
    return;
  }
  ReadScalar(Get(key), Where(key), "a string", value);
}
void OptionsReader::Read(const std::string& key, std::vector<double>* value) {
  if (dumping_) {
    YAML::Node seq(YAML::NodeType::Sequence);
    for (double v : *value) seq.push_back(v);
    seq.SetStyle(YAML::EmitterStyle::Flow);
    node_[key] = seq;
    return;
  }
  const YAML::Node n = Get(key);
  if (!n.IsDefined() || n.IsNull()) return;
  if (!n.IsSequence()) throw ConfigError(Where(key) + ": expected a list of numbers");
  std::vector<double> out;
  for (const auto& item : n) {
    double v = 0;
    ReadScalar(item, Where(key), "a list of numbers", &v);
    out.push_back(v);
  }
  *value = out;
}

OptionsReader OptionsReader::Section(const std::string& key) {
  if (dumping_) {
    if (!node_[key]) node_[key] = YAML::Node(YAML::NodeType::Map);
    OptionsReader child(node_[key], source_, PathOf(key));
    child.dumping_ = true;
    return child;
  }
  const YAML::Node n = Get(key);
  return OptionsReader(n.IsDefined() ? n : YAML::Node(), source_, PathOf(key));
}

void OptionsReader::Finish() const {
  if (dumping_) return;
  if (!node_ || !node_.IsMap()) return;
  std::vector<std::string> known;
  for (const auto& k : read_keys_)
    if (std::find(known.begin(), known.end(), k) == known.end()) known.push_back(k);
  std::string known_list;
  for (const auto& k : known) known_list += (known_list.empty() ? "" : ", ") + k;
  if (known_list.empty()) known_list = "none";
  std::string msg;
  for (const auto& kv : node_) {
    // A key that is itself a list or mapping ("? [a, b]: 1") can never be known; name it by
    // its line (found by fuzz/options_fuzzer: as<std::string>() threw a YAML exception).
    const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : "<non-scalar key>";
    if (kv.first.IsScalar() && std::find(known.begin(), known.end(), k) != known.end()) continue;
    if (!msg.empty()) msg += "\n";
    msg += AtLine(source_, kv.first.Mark().line + 1) + ": " + PathOf(k) +
           ": unknown key (known: " + known_list + ")";
  }
  if (!msg.empty()) throw ConfigError(msg);
}

void CheckOption(bool ok, const std::string& key, const std::string& rule, double value) {
  if (ok) return;
  std::ostringstream msg;
  msg << rule << ", got " << value;
  throw ConfigError(key, msg.str());
}

}  // namespace cslam
