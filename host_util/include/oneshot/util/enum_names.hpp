/// @file enum_names.hpp
/// @brief One table per enumeration of its values and their names: the value is written,
///        read back and listed (in refusals and option checks) from the same entries.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace oneshot::util {

/// A value of the enumeration E and the name it is written and read as.
template <typename E>
struct EnumName {
  E value;           ///< The value.
  const char* name;  ///< Its name.
};

/// The name of `value` in `table` ("?" when the table lacks it).
template <typename E, std::size_t N>
constexpr const char* enum_name(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& e : table)
    if (e.value == value) return e.name;
  return "?";
}

/// The value named `name` in `table`, or nothing.
template <typename E, std::size_t N>
std::optional<E> enum_value(const EnumName<E> (&table)[N], const std::string& name) {
  for (const EnumName<E>& e : table)
    if (name == e.name) return e.value;
  return std::nullopt;
}

/// The names of `table`, in its order.
template <typename E, std::size_t N>
std::vector<std::string> enum_names(const EnumName<E> (&table)[N]) {
  std::vector<std::string> names;
  for (const EnumName<E>& e : table) names.emplace_back(e.name);
  return names;
}

/// The names of `table` joined by ", " (what a refusal lists as accepted).
template <typename E, std::size_t N>
std::string enum_name_list(const EnumName<E> (&table)[N]) {
  std::string list;
  for (const EnumName<E>& e : table) list += (list.empty() ? "" : ", ") + std::string(e.name);
  return list;
}

}  // namespace oneshot::util
