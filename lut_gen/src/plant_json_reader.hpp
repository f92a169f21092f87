/// @file plant_json_reader.hpp
/// @brief Strict JSON reading for plant files: bounded file reads, duplicate keys refused,
///        typed field access whose errors name the source and the field (internal header).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design::detail {

/// Largest plant file read (bytes).
inline constexpr std::uintmax_t kMaxPlantFileBytes = 1u << 20;

/// The text of a regular file of at most kMaxPlantFileBytes; PlantError naming the path
/// and the cause otherwise (missing, a directory, a device or pipe, too large, unreadable).
std::string read_plant_text(const std::string& path);

/// Parses JSON, refusing duplicate keys (nlohmann keeps the last one silently) and
/// invalid text; PlantError names the source.
nlohmann::json parse_strict(const std::string& text, const std::string& source);

/// True for a C identifier ([A-Za-z_][A-Za-z0-9_]*).
bool is_identifier(const std::string& s);

/// Typed access with errors that name the source and the field.
class Checker {
 public:
  /// Errors will name `source`.
  explicit Checker(std::string source) : source_(std::move(source)) {}

  /// Throws PlantError "<source>: field '<field>': <what>".
  [[noreturn]] void fail(const std::string& field, const std::string& what) const;

  /// obj[key]; "is missing" when absent.
  const nlohmann::json& require(const nlohmann::json& obj, const std::string& key, const std::string& path) const;
  /// Refuses keys of obj not in `allowed`.
  void only_keys(const nlohmann::json& obj, const std::string& path, std::initializer_list<const char*> allowed) const;
  /// obj[key] as an object.
  const nlohmann::json& object(const nlohmann::json& obj, const std::string& key, const std::string& path) const;
  /// A finite number.
  double number(const nlohmann::json& v, const std::string& field) const;
  /// obj[key] as a finite number in [min, max] (reported as written when outside).
  double number_in(const nlohmann::json& obj, const std::string& key, const std::string& path, double min_value,
                   double max_value) const;
  /// obj[key] as an integer in [min, max]; an out-of-range value is reported as written.
  std::int64_t integer(const nlohmann::json& obj, const std::string& key, const std::string& path,
                       std::int64_t min_value, std::int64_t max_value) const;
  /// obj[key] as a non-empty rectangular matrix of finite numbers.
  DenseMatrix matrix(const nlohmann::json& obj, const std::string& key, const std::string& path) const;
  /// obj[key] as `expected` finite numbers.
  std::vector<double> vector_of(const nlohmann::json& obj, const std::string& key, const std::string& path,
                                std::size_t expected) const;
  /// Refuses a matrix whose shape is not rows×cols.
  void shape(const DenseMatrix& m, const std::string& field, std::size_t rows, std::size_t cols,
             const std::string& why) const;
  /// Symmetric and positive definite (or semidefinite and non-zero), checked on the
  /// matrix scaled by its largest entry (no overflow of a trace or a pivot).
  void covariance(const DenseMatrix& m, const std::string& field, bool definite, bool allow_zero = false) const;
  /// Identifier names, generated as prefix1… when absent.
  std::vector<std::string> names(const nlohmann::json& obj, const std::string& key, std::size_t expected,
                                 const std::string& prefix) const;
  /// Optional string field ("" when absent).
  std::string optional_string(const nlohmann::json& obj, const std::string& key, const std::string& path) const;

 private:
  std::string source_;
};

}  // namespace oneshot::design::detail
