/// @file plant_json_reader.cpp
/// @brief Strict JSON reading for plant files (see plant_json_reader.hpp).
#include "plant_json_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "oneshot/design/plant_description.hpp"

namespace oneshot::design::detail {

using nlohmann::json;

std::string read_plant_text(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw PlantError(path + ": cannot read the plant file (no such file)");
  if (fs::is_directory(st)) throw PlantError(path + ": is a directory, not a plant file");
  if (!fs::is_regular_file(st)) {
    throw PlantError(path + ": is not a regular file (a device, pipe or socket); give a JSON file");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > kMaxPlantFileBytes) {
    throw PlantError(path + ": the plant file has " + std::to_string(size) + " bytes, more than the limit of " +
                     std::to_string(kMaxPlantFileBytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PlantError(path + ": cannot read the plant file");
  std::string text(kMaxPlantFileBytes + 1, '\0');  // +1: detects a file that grew past the limit
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw PlantError(path + ": error while reading the plant file");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxPlantFileBytes) {
    throw PlantError(path + ": the plant file is larger than the limit of " + std::to_string(kMaxPlantFileBytes) +
                     " bytes");
  }
  return text;
}

json parse_strict(const std::string& text, const std::string& source) {
  // One set of keys per open object; a non-object container pushes nothing but "[]".
  std::vector<std::set<std::string>> seen;
  std::vector<std::string> path;
  std::string duplicate;
  const json::parser_callback_t callback = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        seen.emplace_back();
        path.emplace_back();
        break;
      case json::parse_event_t::object_end:
        if (!seen.empty()) seen.pop_back();
        if (!path.empty()) path.pop_back();
        break;
      case json::parse_event_t::array_start: path.emplace_back("[]"); break;
      case json::parse_event_t::array_end:
        if (!path.empty()) path.pop_back();
        break;
      case json::parse_event_t::key: {
        const std::string key = parsed.get<std::string>();
        if (!seen.empty() && !seen.back().insert(key).second && duplicate.empty()) {
          std::string where;
          for (std::size_t i = 0; i + 1 < path.size(); ++i) {
            if (path[i] == "[]") {
              where += "[]";
            } else if (!path[i].empty()) {
              where += (where.empty() ? "" : ".") + path[i];
            }
          }
          duplicate = where.empty() ? key : where + "." + key;
        }
        if (!path.empty()) path.back() = key;
        break;
      }
      case json::parse_event_t::value: break;
    }
    return true;
  };
  json root;
  try {
    root = json::parse(text, callback);
  } catch (const json::exception& e) {
    throw PlantError(source + ": not valid JSON: " + e.what());
  }
  if (!duplicate.empty()) {
    throw PlantError(source, duplicate, "given twice (duplicate JSON key)");
  }
  return root;
}

bool is_identifier(const std::string& s) {
  return !s.empty() && (std::isalpha(static_cast<unsigned char>(s[0])) != 0 || s[0] == '_') &&
         std::all_of(s.begin(), s.end(),
                     [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_'; });
}

void Checker::fail(const std::string& field, const std::string& what) const {
  throw PlantError(source_, field, what);
}

const json& Checker::require(const json& obj, const std::string& key, const std::string& path) const {
  const auto it = obj.find(key);
  if (it == obj.end()) fail(path + key, "is missing");
  return *it;
}

void Checker::only_keys(const json& obj, const std::string& path, std::initializer_list<const char*> allowed) const {
  for (const auto& item : obj.items()) {
    const bool known =
        std::any_of(allowed.begin(), allowed.end(), [&](const char* k) { return item.key() == k; });
    if (!known) {
      std::string list;
      for (const char* k : allowed) list += std::string(list.empty() ? "" : ", ") + k;
      fail(path + item.key(), "unknown field (expected one of: " + list + ")");
    }
  }
}

const json& Checker::object(const json& obj, const std::string& key, const std::string& path) const {
  const json& v = require(obj, key, path);
  if (!v.is_object()) fail(path + key, "must be an object");
  return v;
}

double Checker::number(const json& v, const std::string& field) const {
  if (!v.is_number()) fail(field, "must be a number, got " + std::string(v.type_name()));
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(field, "must be finite, got " + v.dump());
  return d;
}

double Checker::number_in(const json& obj, const std::string& key, const std::string& path, double min_value,
                          double max_value) const {
  const double d = number(require(obj, key, path), path + key);
  if (d < min_value || d > max_value) {
    std::ostringstream o;
    o << "must be in [" << min_value << ", " << max_value << "], got " << obj.at(key).dump();
    fail(path + key, o.str());
  }
  return d;
}

std::int64_t Checker::integer(const json& obj, const std::string& key, const std::string& path,
                              std::int64_t min_value, std::int64_t max_value) const {
  const json& v = require(obj, key, path);
  if (!v.is_number_integer()) fail(path + key, "must be an integer, got " + v.dump());
  const bool too_big = v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(max_value);
  if (too_big || v.get<std::int64_t>() < min_value || v.get<std::int64_t>() > max_value) {
    // v.dump() prints the number as written: 2^64 − 1 stays 18446744073709551615, not −1.
    fail(path + key, "must be in [" + std::to_string(min_value) + ", " + std::to_string(max_value) + "], got " +
                         v.dump());
  }
  return v.get<std::int64_t>();
}

DenseMatrix Checker::matrix(const json& obj, const std::string& key, const std::string& path) const {
  const std::string field = path + key;
  const json& v = require(obj, key, path);
  if (!v.is_array() || v.empty()) fail(field, "must be a non-empty array of rows");
  DenseMatrix m;
  m.rows = v.size();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const json& row = v[i];
    const std::string row_field = field + "[" + std::to_string(i) + "]";
    if (!row.is_array() || row.empty()) fail(row_field, "must be a non-empty array of numbers");
    if (i == 0) m.cols = row.size();
    if (row.size() != m.cols) {
      fail(row_field, "has " + std::to_string(row.size()) + " entries, row 0 has " + std::to_string(m.cols));
    }
    for (std::size_t j = 0; j < row.size(); ++j)
      m.values.push_back(number(row[j], row_field + "[" + std::to_string(j) + "]"));
  }
  return m;
}

std::vector<double> Checker::vector_of(const json& obj, const std::string& key, const std::string& path,
                                       std::size_t expected) const {
  const std::string field = path + key;
  const json& v = require(obj, key, path);
  if (!v.is_array()) fail(field, "must be an array of numbers");
  if (v.size() != expected) {
    fail(field, "must have " + std::to_string(expected) + " entries, has " + std::to_string(v.size()));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(number(v[i], field + "[" + std::to_string(i) + "]"));
  return out;
}

void Checker::shape(const DenseMatrix& m, const std::string& field, std::size_t rows, std::size_t cols,
                    const std::string& why) const {
  if (m.rows != rows || m.cols != cols) {
    fail(field, "must be " + std::to_string(rows) + "x" + std::to_string(cols) + " (" + why + "), got " +
                    std::to_string(m.rows) + "x" + std::to_string(m.cols));
  }
}

void Checker::covariance(const DenseMatrix& m, const std::string& field, bool definite, bool allow_zero) const {
  const std::size_t n = m.rows;
  double scale = 0;
  for (double x : m.values) scale = std::max(scale, std::fabs(x));
  if (!(scale > 0)) {
    if (allow_zero && !definite) return;
    fail(field, definite ? "must be positive definite (it is zero)" : "must be positive semidefinite and non-zero");
  }
  // Work on M / max|m_ij|: entries in [−1, 1], so neither the trace nor a pivot overflows.
  DenseMatrix l = m;
  for (double& x : l.values) x /= scale;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (std::fabs(l(i, j) - l(j, i)) > 1e-12) fail(field, "must be symmetric");
  double trace = 0;
  for (std::size_t i = 0; i < n; ++i) trace += l(i, i);
  if (!(trace > 0)) {
    fail(field, definite ? "must be positive definite (its trace is not positive)"
                         : "must be positive semidefinite (its trace is not positive)");
  }
  const double shift = definite ? 0.0 : 1e-12 * trace;
  for (std::size_t i = 0; i < n; ++i) l(i, i) += shift;
  for (std::size_t j = 0; j < n; ++j) {
    double d = l(j, j);
    for (std::size_t k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    if (!(d > 1e-14 * trace)) fail(field, definite ? "must be positive definite" : "must be positive semidefinite");
    l(j, j) = std::sqrt(d);
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = l(i, j);
      for (std::size_t k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
      l(i, j) = s / l(j, j);
    }
  }
}

std::vector<std::string> Checker::names(const json& obj, const std::string& key, std::size_t expected,
                                        const std::string& prefix) const {
  const auto it = obj.find(key);
  std::vector<std::string> out;
  if (it == obj.end()) {
    for (std::size_t i = 0; i < expected; ++i) out.push_back(prefix + std::to_string(i + 1));
    return out;
  }
  if (!it->is_array()) fail(key, "must be an array of names");
  if (it->size() != expected) {
    fail(key, "must have " + std::to_string(expected) + " names, has " + std::to_string(it->size()));
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < it->size(); ++i) {
    const json& v = (*it)[i];
    const std::string field = key + "[" + std::to_string(i) + "]";
    if (!v.is_string()) fail(field, "must be a string");
    const std::string s = v.get<std::string>();
    if (!is_identifier(s)) fail(field, "must be an identifier ([A-Za-z_][A-Za-z0-9_]*), got '" + s + "'");
    if (!seen.insert(s).second) fail(field, "duplicate name '" + s + "'");
    out.push_back(s);
  }
  return out;
}

std::string Checker::optional_string(const json& obj, const std::string& key, const std::string& path) const {
  const auto it = obj.find(key);
  if (it == obj.end()) return {};
  if (!it->is_string()) fail(path + key, "must be a string");
  return it->get<std::string>();
}

}  // namespace oneshot::design::detail
