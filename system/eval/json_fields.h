#pragma once
// One description per serialized struct: a table of {JSON key, member} that the writer and the
// reader both walk, so a field cannot be written under one key and read under another, and a
// new field is one row. A struct takes part by specialising JsonFields:
//
//   template <> struct JsonFields<Foo> {
//     static constexpr auto kFields = std::tuple{JsonField{"a_m", &Foo::a_m}, ...};
//   };
//
// Member kinds and their JSON: std::optional<number or string> (empty, NaN and infinity are
// null: JSON has no spelling for the last two), plain values (string, int, bool, vector<int>),
// a described struct (an object), a vector of described structs (an array of objects).
// Reading: a missing key or null leaves the member at its default; a present value of the
// wrong type is an InputError naming the file and the key path.
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/errors.h"

namespace cslam {

/// One row of a field table: the JSON key and the member it holds.
template <typename Struct, typename Member>
struct JsonField {
  const char* key;
  Member Struct::*member;
};
template <typename Struct, typename Member>
JsonField(const char*, Member Struct::*) -> JsonField<Struct, Member>;

/// The field table of `Struct` (`static constexpr auto kFields`, a tuple of JsonField), in the
/// order the struct declares them; specialised next to each serialized struct.
template <typename Struct>
struct JsonFields;

/// A struct with a field table.
template <typename T>
concept JsonDescribed = requires {
  JsonFields<T>::kFields;
};

/// Calls `f(field)` for every row of `Struct`'s table, in order.
template <JsonDescribed Struct, typename F>
void ForEachJsonField(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, JsonFields<Struct>::kFields);
}

namespace json_fields_internal {

template <typename T>
struct IsOptional : std::false_type {};
template <typename T>
struct IsOptional<std::optional<T>> : std::true_type {};

template <typename T>
struct DescribedVector : std::false_type {};
template <JsonDescribed T>
struct DescribedVector<std::vector<T>> : std::true_type {};

inline std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

}  // namespace json_fields_internal

template <JsonDescribed Struct>
nlohmann::json FieldsToJson(const Struct& s);
template <JsonDescribed Struct>
void FieldsFromJson(const nlohmann::json& j, Struct& s, const std::string& source,
                    const std::string& path = "");

/// The JSON of one member value (see the file comment).
template <typename T>
nlohmann::json FieldValueToJson(const T& v) {
  using namespace json_fields_internal;
  if constexpr (JsonDescribed<T>) {
    return FieldsToJson(v);
  } else if constexpr (DescribedVector<T>::value) {
    nlohmann::json array = nlohmann::json::array();
    for (const auto& e : v) array.push_back(FieldsToJson(e));
    return array;
  } else if constexpr (IsOptional<T>::value) {
    if (!v) return nullptr;
    if constexpr (std::is_floating_point_v<typename T::value_type>) {
      if (!std::isfinite(*v)) return nullptr;
    }
    return *v;
  } else {
    return v;
  }
}

/// Reads one member value from `j` (not null); `path` names it in errors.
template <typename T>
void FieldValueFromJson(const nlohmann::json& j, T& out, const std::string& source,
                        const std::string& path) {
  using namespace json_fields_internal;
  if constexpr (JsonDescribed<T>) {
    FieldsFromJson(j, out, source, path);
  } else if constexpr (DescribedVector<T>::value) {
    if (!j.is_array()) throw InputError(source, path + ": expected a JSON array");
    out.clear();
    for (size_t i = 0; i < j.size(); ++i)
      FieldValueFromJson(j[i], out.emplace_back(), source, path + "[" + std::to_string(i) + "]");
  } else {
    try {
      if constexpr (IsOptional<T>::value)
        out = j.get<typename T::value_type>();
      else
        out = j.get<T>();
    } catch (const nlohmann::json::exception& e) {
      throw InputError(source, path + ": unexpected value type: " + e.what());
    }
  }
}

/// The object holding every field of `s`'s table.
template <JsonDescribed Struct>
nlohmann::json FieldsToJson(const Struct& s) {
  nlohmann::json j = nlohmann::json::object();
  ForEachJsonField<Struct>(
      [&](const auto& field) { j[field.key] = FieldValueToJson(s.*field.member); });
  return j;
}

/// Reads the fields of `s`'s table from the object `j`; keys that are missing or null leave
/// their member as it is, other keys are ignored. Throws InputError(source) naming `path`.
template <JsonDescribed Struct>
void FieldsFromJson(const nlohmann::json& j, Struct& s, const std::string& source,
                    const std::string& path) {
  using json_fields_internal::Join;
  if (!j.is_object())
    throw InputError(source, (path.empty() ? "" : path + ": ") + "expected a JSON object");
  ForEachJsonField<Struct>([&](const auto& field) {
    const auto it = j.find(field.key);
    if (it != j.end() && !it->is_null())
      FieldValueFromJson(*it, s.*field.member, source, Join(path, field.key));
  });
}

}  // namespace cslam
