#pragma once
// One configuration path: YAML → OptionsReader → Options structs. Every key read is recorded,
// and a section is always loaded through LoadInto / ReadSection, which reject any key its Load
// did not read, so a misspelt key anywhere in the tree is an error instead of a silent
// default. Errors are ConfigError naming the file, the line and the dotted key path as
// written in the YAML ("config.yaml:3: backend.max_iteration: unknown key (known: …)").
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/errors.h"

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
  /// A word of `table` (core/enum_names.h); any other word is an error listing the table's.
  template <typename Enum, std::size_t N>
  void Read(const std::string& key, const EnumName<Enum> (&table)[N], Enum* value) {
    std::string name = NameOf(table, *value);
    Read(key, &name);
    if (dumping_) return;
    try {
      *value = ParseEnum(table, name, key);
    } catch (const ConfigError& e) {
      throw ConfigError(Where(key) + ": " + e.rule());
    }
  }

  /// Loads `*options` (anything with `void Load(OptionsReader&)`) from this reader's whole
  /// mapping, then rejects every key its Load did not read. For the document's root.
  template <typename Options>
  void LoadInto(Options* options) {
    options->Load(*this);
    Finish();
  }
  /// Loads `*options` from the nested mapping `key` the same way (absent: its values stay).
  /// The only way a Load reads a sub-section, so no section can skip the unknown-key check.
  template <typename Options>
  void ReadSection(const std::string& key, Options* options) {
    OptionsReader section = Section(key);
    section.LoadInto(options);
  }

  /// "file:line: key.path" for messages (no line when the key is absent).
  std::string Where(const std::string& key) const;
  /// The line (1-based) of the key at the dotted `path` below this mapping; 0 when absent.
  int LineOf(const std::string& path) const;

 private:
  YAML::Node Get(const std::string& key);
  OptionsReader Section(const std::string& key);
  void Finish() const;
  std::string PathOf(const std::string& key) const;

  YAML::Node node_;
  std::string source_;
  std::string path_;
  std::vector<std::string> read_keys_;
  bool dumping_ = false;
};

/// Throws ConfigError(key, "<rule>, got <value>") unless `ok`. For Options::Check(), which
/// names keys relative to its own section; CheckSection adds the enclosing sections' names.
void CheckOption(bool ok, const std::string& key, const std::string& rule, double value);

/// Runs `check` (a nested section's Check()) and prefixes `section.` to the key path of the
/// ConfigError it throws, so the message names the key as the YAML nests it.
template <typename CheckFn>
void CheckSection(const std::string& section, CheckFn&& check) {
  try {
    check();
  } catch (const ConfigError& e) {
    if (e.key().empty()) throw ConfigError(section + "." + e.what());
    throw ConfigError(section + "." + e.key(), e.rule());
  }
}

}  // namespace cslam
