/// @file strict_json.hpp
/// @brief JSON read strictly and written only when every number is finite (host only).
///
/// nlohmann::json keeps the last of two equal keys and writes NaN and ±Inf as `null`: a
/// typo'd duplicate in an input file would silently override a value, and a diverged
/// result would reach a report as `null` with exit status 0. These helpers refuse both.
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace oneshot::util {

/// Invalid or ambiguous JSON; what() says where (a key path such as scenarios[1].name).
class JsonError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses `text`; JsonError for invalid JSON ("not valid JSON: …") or an object with the
/// same key twice ("field 'a.b': duplicate key").
nlohmann::json parse_json_strict(const std::string& text);

/// Key path of the first NaN, infinite number or null in `j` ("" when there is none).
/// The root itself is reported as "(top level)".
std::string first_non_finite(const nlohmann::json& j);

/// Key path of the first NaN or infinite number in `j` ("" when there is none); nulls pass.
std::string first_non_finite_number(const nlohmann::json& j);

/// `j` dumped with `indent`; JsonError naming the field when it holds a NaN or infinite
/// number (nlohmann would write it as `null`). An explicit null that a result sets on purpose
/// (an unbounded δt, a divergent MARE) is written as null, next to the reason the study gives.
std::string dump_finite(const nlohmann::json& j, int indent = 2);

}  // namespace oneshot::util
