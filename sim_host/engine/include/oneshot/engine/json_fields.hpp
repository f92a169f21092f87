/// @file json_fields.hpp
/// @brief Strict JSON reading for the engine's files: duplicate and unknown keys refused,
///        every value type- and range-checked, every error naming the field.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace oneshot::engine {

/// An input file or value that failed validation; what() names the field.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Parses JSON text, refusing duplicate keys in any object ("source: duplicate key 'k'") and
/// nesting deeper than 32 levels, and reporting syntax errors with their position.
nlohmann::json parse_json_strict(const std::string& text, const std::string& source);

/// `where` must be an object whose keys are all in `known` (InputError naming the first other).
void require_keys(const nlohmann::json& j, const std::string& where, std::initializer_list<const char*> known);

/// Required member `key` of object `j` (InputError "where.key: missing").
const nlohmann::json& member(const nlohmann::json& j, const std::string& where, const char* key);

/// `v` in the fewest significant digits (%g style, 6 to 17) that read back as `v`: how refusals
/// print a range's bounds (1.000001 as itself, not as 1).
std::string shortest_number(double v);

/// Number `key` in [lo, hi] (finite); `fallback` when absent and `optional`.
double number_in(const nlohmann::json& j, const std::string& where, const char* key, double lo, double hi,
                 bool optional = false, double fallback = 0);

/// Integer `key` in [lo, hi]; `fallback` when absent and `optional`.
std::int64_t integer_in(const nlohmann::json& j, const std::string& where, const char* key, std::int64_t lo,
                        std::int64_t hi, bool optional = false, std::int64_t fallback = 0);

/// String `key` (non-empty); `fallback` when absent and `optional`.
std::string string_of(const nlohmann::json& j, const std::string& where, const char* key, bool optional = false,
                      const std::string& fallback = {});

/// Boolean `key`; `fallback` when absent.
bool boolean_of(const nlohmann::json& j, const std::string& where, const char* key, bool fallback);

}  // namespace oneshot::engine
