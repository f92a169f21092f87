/// @file study_fields.hpp
/// @brief How the study runner names a file's fields when it refuses one: "list[i]" and the
///        one-line engine::InputError "field '<field>': <reason>".
#pragma once

#include <cstddef>
#include <string>

#include "oneshot/engine/json_fields.hpp"

namespace oneshot::study {

/// "list[i]": the i-th element of the file's list `list`.
inline std::string at(const char* list, std::size_t i) { return std::string(list) + "[" + std::to_string(i) + "]"; }

/// Refuses the file: engine::InputError "field '<field>': <why>".
[[noreturn]] inline void refuse(const std::string& field, const std::string& why) {
  throw engine::InputError("field '" + field + "': " + why);
}

}  // namespace oneshot::study
