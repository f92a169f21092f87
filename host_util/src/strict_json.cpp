/// @file strict_json.cpp
/// @brief Duplicate-key detection and finite-number checks (see strict_json.hpp).
#include "oneshot/util/strict_json.hpp"

#include <cmath>
#include <set>
#include <vector>

namespace oneshot::util {
namespace {

using json = nlohmann::json;

/// Deepest nesting accepted: our files are a few levels deep; this bounds the parser's memory.
constexpr std::size_t kMaxDepth = 64;

/// One open object or array while parsing: where we are and what keys it has.
struct Level {
  bool array = false;
  long index = -1;  // current element of an array
  std::string key;  // current key of an object
  std::set<std::string> keys;
};

std::string path_of(const std::vector<Level>& stack) {
  std::string p;
  for (const Level& l : stack) {
    if (l.array) {
      if (l.index >= 0) p += "[" + std::to_string(l.index) + "]";
    } else if (!l.key.empty() || !l.keys.empty()) {
      p += (p.empty() ? "" : ".") + l.key;
    }
  }
  return p;
}

std::string non_finite_in(const json& j, const std::string& path, bool null_is_bad) {
  const auto at = [&](const std::string& p) { return p.empty() ? std::string("(top level)") : p; };
  switch (j.type()) {
    case json::value_t::null:
      return null_is_bad ? at(path) : std::string();
    case json::value_t::number_float:
      return std::isfinite(j.get<double>()) ? std::string() : at(path);
    case json::value_t::object:
      for (const auto& [k, v] : j.items()) {
        const std::string r = non_finite_in(v, path.empty() ? k : path + "." + k, null_is_bad);
        if (!r.empty()) return r;
      }
      return {};
    case json::value_t::array:
      for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string r = non_finite_in(j[i], path + "[" + std::to_string(i) + "]", null_is_bad);
        if (!r.empty()) return r;
      }
      return {};
    default:
      return {};
  }
}

}  // namespace

json parse_json_strict(const std::string& text) {
  std::vector<Level> stack;
  std::string duplicate;
  // An element of an array starts with a value, an object or an array at its level.
  const auto element_starts = [&] {
    if (!stack.empty() && stack.back().array) ++stack.back().index;
    if (stack.size() >= kMaxDepth) {
      throw JsonError("not valid here: nested deeper than " + std::to_string(kMaxDepth) + " levels at '" +
                      path_of(stack) + "'");
    }
  };
  const json::parser_callback_t cb = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        element_starts();
        stack.push_back(Level{});
        break;
      case json::parse_event_t::array_start:
        element_starts();
        stack.push_back(Level{true, -1, {}, {}});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case json::parse_event_t::key:
        if (!stack.empty() && duplicate.empty()) {
          const std::string k = parsed.get<std::string>();
          Level& top = stack.back();
          top.key = k;
          if (!top.keys.insert(k).second) duplicate = path_of(stack);
        }
        break;
      case json::parse_event_t::value:
        element_starts();
        break;
    }
    return true;
  };
  json root;
  try {
    root = json::parse(text, cb);
  } catch (const json::exception& e) {
    throw JsonError(std::string("not valid JSON: ") + e.what());
  }
  if (!duplicate.empty()) throw JsonError("field '" + duplicate + "': duplicate key (which value is meant?)");
  return root;
}

std::string first_non_finite(const json& j) { return non_finite_in(j, "", true); }

std::string first_non_finite_number(const json& j) { return non_finite_in(j, "", false); }

std::string dump_finite(const json& j, int indent) {
  const std::string where = first_non_finite_number(j);
  if (!where.empty()) {
    throw JsonError("field '" + where + "' is not a finite number (NaN or infinite): the computation diverged or "
                    "the inputs are out of range; nothing written");
  }
  return j.dump(indent);
}

}  // namespace oneshot::util
