#pragma once
// One configuration path: YAML → OptionsReader → Options structs. Every key read is recorded;
// Finish() turns any key that nobody read into an error naming it, so typos never pass
// silently. Errors are ConfigError with the file and the dotted key path.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace cslam {

/// Reads typed values from one YAML mapping (a section of a config file).
class OptionsReader {
 public:
  /// `source` names the file for messages; `path` is the dotted key prefix ("backend.hac").
  OptionsReader(YAML::Node node, std::string source, std::string path = "");
  /// Loads a YAML file; throws ConfigError when it is missing or not a mapping.
  static OptionsReader FromFile(const std::string& file);
  /// Parses YAML text (for tests and embedded defaults).
  static OptionsReader FromString(const std::string& text, const std::string& source);
  /// A reader in dump mode: every Read stores the current value instead of reading one, so
  /// running an Options::Load on it records the effective configuration; Dump() returns it.
  static OptionsReader ForDump();
  /// The recorded configuration as YAML text (dump mode only).
  std::string Dump() const;
  bool dumping() const { return dumping_; }

  bool Has(const std::string& key) const;
  /// Each Read leaves `*value` unchanged when the key is absent, and throws ConfigError
  /// naming the key when the value has the wrong type.
  void Read(const std::string& key, double* value);
  void Read(const std::string& key, int* value);
  void Read(const std::string& key, bool* value);
  void Read(const std::string& key, std::string* value);
  void Read(const std::string& key, std::vector<double>* value);
  /// A nested mapping; absent → an empty reader.
  OptionsReader Section(const std::string& key);
  /// Throws ConfigError listing the keys of this mapping that were never read.
  void Finish() const;

  /// "file: key.path" for messages.
  std::string Where(const std::string& key) const;

 private:
  YAML::Node Get(const std::string& key);
  YAML::Node node_;
  std::string source_;
  std::string path_;
  std::vector<std::string> read_keys_;
  bool dumping_ = false;
};

/// Throws ConfigError("<key>: <rule>, got <value>") unless `ok`. For Options::Check().
void CheckOption(bool ok, const std::string& key, const std::string& rule, double value);

}  // namespace cslam
