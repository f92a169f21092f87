/// @file json_fields.cpp
/// @brief Strict JSON reading (see json_fields.hpp).
#include "oneshot/engine/json_fields.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>
#include <vector>

namespace oneshot::engine {

namespace {
/// Deepest nesting accepted (the study schema needs 6; a bound keeps hostile input cheap).
constexpr int kMaxDepth = 32;
}  // namespace

nlohmann::json parse_json_strict(const std::string& text, const std::string& source) {
  // Key sets of the objects being parsed (one per nesting level of objects).
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  const nlohmann::json::parser_callback_t check = [&](int depth, nlohmann::json::parse_event_t event,
                                                      nlohmann::json& parsed) {
    if (depth > kMaxDepth) throw InputError(source + ": nested deeper than " + std::to_string(kMaxDepth) + " levels");
    switch (event) {
      case nlohmann::json::parse_event_t::object_start:
        keys.emplace_back();
        break;
      case nlohmann::json::parse_event_t::object_end:
        if (!keys.empty()) keys.pop_back();
        break;
      case nlohmann::json::parse_event_t::key:
        if (!keys.empty() && !keys.back().insert(parsed.get<std::string>()).second && duplicate.empty()) {
          duplicate = parsed.get<std::string>();
        }
        break;
      default:
        break;
    }
    return true;
  };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text, check);
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number beyond double (5001e308): both refused by name.
    throw InputError(source + ": not valid JSON: " + e.what());
  }
  if (!duplicate.empty()) throw InputError(source + ": duplicate key '" + duplicate + "'");
  return j;
}

void require_keys(const nlohmann::json& j, const std::string& where, std::initializer_list<const char*> known) {
  if (!j.is_object()) throw InputError("field '" + where + "': must be an object");
  for (const auto& item : j.items()) {
    bool ok = false;
    for (const char* k : known) ok = ok || item.key() == k;
    if (!ok) {
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw InputError("field '" + where + "." + item.key() + "': unknown field (known: " + list + ")");
    }
  }
}

const nlohmann::json& member(const nlohmann::json& j, const std::string& where, const char* key) {
  const auto it = j.find(key);
  if (it == j.end()) throw InputError("field '" + where + "." + key + "': missing");
  return *it;
}

std::string shortest_number(double v) {
  char b[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(b, sizeof b, "%.*g", digits, v);
    if (std::strtod(b, nullptr) == v) break;
  }
  return b;
}

double number_in(const nlohmann::json& j, const std::string& where, const char* key, double lo, double hi, bool optional,
                 double fallback) {
  const auto it = j.find(key);
  if (it == j.end()) {
    if (optional) return fallback;
    throw InputError("field '" + where + "." + key + "': missing");
  }
  if (!it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < lo || it->get<double>() > hi) {
    std::ostringstream o;
    o << "field '" << where << "." << key << "': must be a number in [" << shortest_number(lo) << ", " << shortest_number(hi) << "]";
    throw InputError(o.str());
  }
  return it->get<double>();
}

std::int64_t integer_in(const nlohmann::json& j, const std::string& where, const char* key, std::int64_t lo,
                        std::int64_t hi, bool optional, std::int64_t fallback) {
  const auto it = j.find(key);
  if (it == j.end()) {
    if (optional) return fallback;
    throw InputError("field '" + where + "." + key + "': missing");
  }
  const bool integral = it->is_number_integer() && (!it->is_number_unsigned() || it->get<std::uint64_t>() <= INT64_MAX);
  if (!integral || it->get<std::int64_t>() < lo || it->get<std::int64_t>() > hi) {
    throw InputError("field '" + where + "." + key + "': must be an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
  }
  return it->get<std::int64_t>();
}

std::string string_of(const nlohmann::json& j, const std::string& where, const char* key, bool optional,
                      const std::string& fallback) {
  const auto it = j.find(key);
  if (it == j.end()) {
    if (optional) return fallback;
    throw InputError("field '" + where + "." + key + "': missing");
  }
  if (!it->is_string() || it->get<std::string>().empty()) {
    throw InputError("field '" + where + "." + key + "': must be a non-empty string");
  }
  return it->get<std::string>();
}

bool boolean_of(const nlohmann::json& j, const std::string& where, const char* key, bool fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_boolean()) throw InputError("field '" + where + "." + key + "': must be true or false");
  return it->get<bool>();
}

}  // namespace oneshot::engine
