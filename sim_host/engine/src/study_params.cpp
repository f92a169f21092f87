/// @file study_params.cpp
/// @brief The `params` of a study file's approaches and scenarios: numbers checked against the
///        schema's ranges (defaults filled in), and word parameters (ParamSpec::words).
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "study_parse_detail.hpp"

namespace oneshot::engine::detail {
namespace {

using nlohmann::json;

/// The spec of `key` in `specs` (null when specs is null); InputError naming `g` when unknown.
const ParamSpec* param_spec(const std::vector<ParamSpec>* specs, const std::string& key, const std::string& g) {
  if (specs == nullptr) return nullptr;
  for (const ParamSpec& p : *specs)
    if (p.name == key) return &p;
  std::string known;
  for (const ParamSpec& p : *specs) known += (known.empty() ? "" : ", ") + p.name;
  throw InputError("field '" + g + "': unknown parameter (known: " + known + ")");
}

}  // namespace

std::map<std::string, double> parse_params(const json& j, const std::string& f, const std::vector<ParamSpec>* specs,
                                           std::map<std::string, std::string>* words) {
  std::map<std::string, double> out;
  const auto it = j.find("params");
  if (it != j.end() && !it->is_object()) throw InputError("field '" + f + ".params': must be an object");
  if (it != j.end()) {
    for (const auto& item : it->items()) {
      const std::string g = f + ".params." + item.key();
      if (item.value().is_string() && words != nullptr) {
        if (specs == nullptr) {  // no schema: any word (the study's mapping checks it)
          (*words)[item.key()] = item.value().get<std::string>();
          continue;
        }
        const ParamSpec* s = param_spec(specs, item.key(), g);
        std::string list;
        bool known = false;
        if (s != nullptr) {
          for (const std::string& w : s->words) {
            known = known || w == item.value().get<std::string>();
            list += (list.empty() ? "" : ", ") + w;
          }
        }
        if (s == nullptr || s->words.empty()) throw InputError("field '" + g + "': must be a finite number");
        if (!known) throw InputError("field '" + g + "': must be one of " + list);
        (*words)[item.key()] = item.value().get<std::string>();
        continue;
      }
      if (!item.value().is_number() || !std::isfinite(item.value().get<double>())) {
        throw InputError("field '" + g + "': must be a finite number");
      }
      const double v = item.value().get<double>();
      if (specs != nullptr) {
        const ParamSpec* s = param_spec(specs, item.key(), g);
        if (!s->words.empty()) {
          std::string list;
          for (const std::string& w : s->words) list += (list.empty() ? "" : ", ") + w;
          throw InputError("field '" + g + "': must be one of " + list + " (a string)");
        }
        std::ostringstream range;
        range << "[" << shortest_number(s->min) << ", " << shortest_number(s->max) << "]";
        if (v < s->min || v > s->max) throw InputError("field '" + g + "': must be in " + range.str());
        if (s->integer && std::floor(v) != v) throw InputError("field '" + g + "': must be a whole number");
      }
      out[item.key()] = v;
    }
  }
  if (specs != nullptr) {
    for (const ParamSpec& p : *specs) {
      if (out.count(p.name) != 0 || !p.words.empty()) continue;
      if (p.required) throw InputError("field '" + f + ".params." + p.name + "': missing");
      out[p.name] = p.fallback;
    }
  }
  return out;
}


}  // namespace oneshot::engine::detail
