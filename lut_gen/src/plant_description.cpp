/// @file plant_description.cpp
/// @brief Parsing and validation of plant description files.
#include "oneshot/design/plant_description.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace oneshot::design {
namespace {

using nlohmann::json;

/// Builds errors that name the source and the field.
class Checker {
 public:
  explicit Checker(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw PlantError(source_ + ": field '" + field + "': " + what);
  }

  const json& require(const json& obj, const std::string& key, const std::string& path) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(path + key, "is missing");
    return *it;
  }

  void only_keys(const json& obj, const std::string& path, std::initializer_list<const char*> allowed) const {
    for (const auto& item : obj.items()) {
      const bool known = std::any_of(allowed.begin(), allowed.end(),
                                     [&](const char* k) { return item.key() == k; });
      if (!known) {
        std::string list;
        for (const char* k : allowed) list += std::string(list.empty() ? "" : ", ") + k;
        fail(path + item.key(), "unknown field (expected one of: " + list + ")");
      }
    }
  }

  const json& object(const json& obj, const std::string& key, const std::string& path) const {
    const json& v = require(obj, key, path);
    if (!v.is_object()) fail(path + key, "must be an object");
    return v;
  }

  double number(const json& v, const std::string& field) const {
    if (!v.is_number()) fail(field, "must be a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(field, "must be finite");
    return d;
  }

  std::int32_t integer(const json& obj, const std::string& key, const std::string& path,
                       std::int64_t min_value, std::int64_t max_value) const {
    const json& v = require(obj, key, path);
    if (!v.is_number_integer()) fail(path + key, "must be an integer");
    const std::int64_t i = v.get<std::int64_t>();
    if (i < min_value || i > max_value) {
      fail(path + key, "must be in [" + std::to_string(min_value) + ", " + std::to_string(max_value) +
                           "], got " + std::to_string(i));
    }
    return static_cast<std::int32_t>(i);
  }

  DenseMatrix matrix(const json& obj, const std::string& key, const std::string& path) const {
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

  std::vector<double> vector_of(const json& obj, const std::string& key, const std::string& path,
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

  void shape(const DenseMatrix& m, const std::string& field, std::size_t rows, std::size_t cols,
             const std::string& why) const {
    if (m.rows != rows || m.cols != cols) {
      fail(field, "must be " + std::to_string(rows) + "x" + std::to_string(cols) + " (" + why + "), got " +
                      std::to_string(m.rows) + "x" + std::to_string(m.cols));
    }
  }

  /// Symmetric and positive (semi)definite, by Cholesky on M (+ a tiny shift for semi).
  void covariance(const DenseMatrix& m, const std::string& field, bool definite) const {
    const std::size_t n = m.rows;
    double scale = 0;
    for (double x : m.values) scale = std::max(scale, std::fabs(x));
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j)
        if (std::fabs(m(i, j) - m(j, i)) > 1e-12 * scale) fail(field, "must be symmetric");
    double trace = 0;
    for (std::size_t i = 0; i < n; ++i) trace += m(i, i);
    if (!(trace > 0)) {
      fail(field, definite ? "must be positive definite (its trace is not positive)"
                           : "must be positive semidefinite and non-zero (its trace is not positive)");
    }
    DenseMatrix l = m;
    const double shift = definite ? 0.0 : 1e-12 * trace;
    for (std::size_t i = 0; i < n; ++i) l(i, i) += shift;
    for (std::size_t j = 0; j < n; ++j) {
      double d = l(j, j);
      for (std::size_t k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
      if (!(d > 1e-14 * trace)) {
        fail(field, definite ? "must be positive definite" : "must be positive semidefinite");
      }
      l(j, j) = std::sqrt(d);
      for (std::size_t i = j + 1; i < n; ++i) {
        double s = l(i, j);
        for (std::size_t k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
        l(i, j) = s / l(j, j);
      }
    }
  }

  std::vector<std::string> names(const json& obj, const std::string& key, std::size_t expected,
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
      const bool ident = !s.empty() && (std::isalpha(static_cast<unsigned char>(s[0])) != 0 || s[0] == '_') &&
                         std::all_of(s.begin(), s.end(), [](char ch) {
                           return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_';
                         });
      if (!ident) fail(field, "must be an identifier ([A-Za-z_][A-Za-z0-9_]*), got '" + s + "'");
      if (!seen.insert(s).second) fail(field, "duplicate name '" + s + "'");
      out.push_back(s);
    }
    return out;
  }

 private:
  std::string source_;
};

std::string optional_string(const json& obj, const char* key, const Checker& check) {
  const auto it = obj.find(key);
  if (it == obj.end()) return {};
  if (!it->is_string()) check.fail(key, "must be a string");
  return it->get<std::string>();
}

}  // namespace

PlantDescription parse_plant(const std::string& json_text, const std::string& source) {
  const Checker check(source);
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {
    throw PlantError(source + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) throw PlantError(source + ": the plant description must be a JSON object");
  check.only_keys(root, "", {"name", "description", "states", "inputs", "outputs", "A", "B", "C",
                             "period_us", "cost", "noise", "table", "board"});
  PlantDescription p;
  p.source = source;
  p.name = optional_string(root, "name", check);
  if (p.name.empty()) p.name = "plant";
  p.description = optional_string(root, "description", check);

  p.a = check.matrix(root, "A", "");
  const std::size_t n = p.a.rows;
  check.shape(p.a, "A", n, n, "A must be square");
  if (n > kMaxStates) {
    check.fail("A", std::to_string(n) + " states exceed the supported maximum of " + std::to_string(kMaxStates));
  }
  p.b = check.matrix(root, "B", "");
  if (p.b.rows != n) check.shape(p.b, "B", n, p.b.cols, "one row per state");
  const std::size_t m = p.b.cols;
  if (m > kMaxInputs) {
    check.fail("B", std::to_string(m) + " inputs exceed the supported maximum of " + std::to_string(kMaxInputs));
  }
  p.c = check.matrix(root, "C", "");
  if (p.c.cols != n) check.shape(p.c, "C", p.c.rows, n, "one column per state");
  const std::size_t outs = p.c.rows;
  if (outs > kMaxOutputs) {
    check.fail("C", std::to_string(outs) + " outputs exceed the supported maximum of " +
                        std::to_string(kMaxOutputs));
  }
  p.states = check.names(root, "states", n, "x");
  p.inputs = check.names(root, "inputs", m, "u");
  p.outputs = check.names(root, "outputs", outs, "y");

  p.period_us = check.integer(root, "period_us", "", 1, 60'000'000);

  const json& cost = check.object(root, "cost", "");
  check.only_keys(cost, "cost.", {"Q1c", "Q2c"});
  p.q1c = check.matrix(cost, "Q1c", "cost.");
  check.shape(p.q1c, "cost.Q1c", n, n, "one row and column per state");
  check.covariance(p.q1c, "cost.Q1c", false);
  p.q2c = check.matrix(cost, "Q2c", "cost.");
  check.shape(p.q2c, "cost.Q2c", m, m, "one row and column per input");
  check.covariance(p.q2c, "cost.Q2c", true);

  const json& noise = check.object(root, "noise", "");
  check.only_keys(noise, "noise.", {"process_covariance", "measurement_covariance", "initial_covariance"});
  p.process_covariance = check.matrix(noise, "process_covariance", "noise.");
  check.shape(p.process_covariance, "noise.process_covariance", n, n, "one row and column per state");
  check.covariance(p.process_covariance, "noise.process_covariance", false);
  p.measurement_covariance = check.matrix(noise, "measurement_covariance", "noise.");
  check.shape(p.measurement_covariance, "noise.measurement_covariance", outs, outs, "one row and column per output");
  check.covariance(p.measurement_covariance, "noise.measurement_covariance", true);
  if (noise.contains("initial_covariance")) {
    p.has_initial_covariance = true;
    p.initial_covariance = check.matrix(noise, "initial_covariance", "noise.");
    check.shape(p.initial_covariance, "noise.initial_covariance", n, n, "one row and column per state");
    check.covariance(p.initial_covariance, "noise.initial_covariance", true);
  }

  const json& table = check.object(root, "table", "");
  check.only_keys(table, "table.", {"granularity_us", "range_us", "max_bytes"});
  p.table_granularity_us = check.integer(table, "granularity_us", "table.", 1, 10'000'000);
  p.table_range_us = check.integer(table, "range_us", "table.", 1, 60'000'000);
  if (p.table_range_us % p.table_granularity_us != 0) {
    check.fail("table.range_us", "must be a multiple of table.granularity_us (" +
                                     std::to_string(p.table_granularity_us) + ")");
  }
  if (p.table_range_us / p.table_granularity_us > 4096) {
    check.fail("table.range_us", "more than 4096 grid steps of table.granularity_us");
  }
  p.table_max_bytes = check.integer(table, "max_bytes", "table.", 1, 1 << 20);

  const json& board = check.object(root, "board", "");
  check.only_keys(board, "board.", {"pwm_frequency_hz", "pwm_duty_steps", "pwm_low_volts", "pwm_high_volts",
                                    "adc_bits", "adc_min_volts", "adc_max_volts"});
  BoardDescription& bd = p.board;
  bd.pwm_frequency_hz = check.number(check.require(board, "pwm_frequency_hz", "board."), "board.pwm_frequency_hz");
  if (!(bd.pwm_frequency_hz > 0) || bd.pwm_frequency_hz > 1e7) {
    check.fail("board.pwm_frequency_hz", "must be in (0, 1e7] Hz");
  }
  bd.pwm_duty_steps = check.integer(board, "pwm_duty_steps", "board.", 1, 1 << 20);
  bd.pwm_low_volts = check.vector_of(board, "pwm_low_volts", "board.", m);
  bd.pwm_high_volts = check.vector_of(board, "pwm_high_volts", "board.", m);
  for (std::size_t j = 0; j < m; ++j)
    if (!(bd.pwm_low_volts[j] < bd.pwm_high_volts[j])) {
      check.fail("board.pwm_high_volts[" + std::to_string(j) + "]", "must be above board.pwm_low_volts");
    }
  bd.adc_bits = check.integer(board, "adc_bits", "board.", 1, 24);
  bd.adc_min_volts = check.vector_of(board, "adc_min_volts", "board.", outs);
  bd.adc_max_volts = check.vector_of(board, "adc_max_volts", "board.", outs);
  for (std::size_t j = 0; j < outs; ++j)
    if (!(bd.adc_min_volts[j] < bd.adc_max_volts[j])) {
      check.fail("board.adc_max_volts[" + std::to_string(j) + "]", "must be above board.adc_min_volts");
    }
  return p;
}

PlantDescription load_plant_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PlantError(path + ": cannot read the plant file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw PlantError(path + ": error while reading the plant file");
  return parse_plant(text.str(), path);
}

PlantDescription reference_plant() { return parse_plant(reference_plant_json(), "built-in reference board"); }

}  // namespace oneshot::design
