#pragma once
// One table per enum that a config file or the command line spells as a word: the table is
// the only place the spellings live, so parsing, printing, the YAML reader's error message
// and the CLI's list of allowed values cannot disagree.
#include <cstddef>
#include <string>
#include <vector>

#include "core/errors.h"

namespace cslam {

/// One row of an enum's spelling table: the value and the one word that names it.
template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

/// The word for `value` in `table`; "?" for a value missing from the table (a bug).
template <typename Enum, std::size_t N>
std::string NameOf(const EnumName<Enum> (&table)[N], Enum value) {
  for (const auto& row : table)
    if (row.value == value) return row.name;
  return "?";
}

/// Every word of `table`, in table order (for CLI11's IsMember and for messages).
template <typename Enum, std::size_t N>
std::vector<std::string> NamesOf(const EnumName<Enum> (&table)[N]) {
  std::vector<std::string> names;
  for (const auto& row : table) names.emplace_back(row.name);
  return names;
}

/// "a, b, c".
template <typename Enum, std::size_t N>
std::string NameList(const EnumName<Enum> (&table)[N]) {
  std::string list;
  for (const auto& row : table) list += (list.empty() ? "" : ", ") + std::string(row.name);
  return list;
}

/// The value named `text`; throws ConfigError(key, "must be one of …, got '…'") otherwise.
template <typename Enum, std::size_t N>
Enum ParseEnum(const EnumName<Enum> (&table)[N], const std::string& text, const std::string& key) {
  for (const auto& row : table)
    if (text == row.name) return row.value;
  throw ConfigError(key, "must be one of " + NameList(table) + ", got '" + text + "'");
}

}  // namespace cslam
