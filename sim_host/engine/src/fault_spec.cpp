/// @file fault_spec.cpp
/// @brief Parsing of fault-injection specs (see fault_spec.hpp).
#include "oneshot/engine/fault_spec.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "oneshot/engine/json_fields.hpp"

namespace oneshot::engine {
namespace {

struct KindInfo {
  FaultClause::Kind kind;
  const char* name;
  const char* keys;  ///< Accepted keys, for messages.
};

constexpr KindInfo kKinds[] = {
    {FaultClause::Kind::kNan, "nan", "link, rate, at_s"},
    {FaultClause::Kind::kFlip, "flip", "link, rate, at_s, bits"},
    {FaultClause::Kind::kDup, "dup", "link, rate, at_s"},
    {FaultClause::Kind::kReplay, "replay", "link, rate, at_s, age_ms"},
    {FaultClause::Kind::kForgeSeq, "forge_seq", "link, rate, at_s, jump"},
    {FaultClause::Kind::kRestart, "restart", "node, at_s"},
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\n')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

/// A whole finite number in [lo, hi]; InputError naming `where` otherwise.
double number_in(std::string_view text, double lo, double hi, const std::string& where) {
  const std::string s(text);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
    throw InputError(where + ": '" + s + "' is not a number");
  }
  if (!(v >= lo && v <= hi)) {
    char b[128];
    std::snprintf(b, sizeof b, ": %s is out of range [%g, %g]", s.c_str(), lo, hi);
    throw InputError(where + b);
  }
  return v;
}

double integer_in(std::string_view text, double lo, double hi, const std::string& where) {
  const double v = number_in(text, lo, hi, where);
  if (v != std::floor(v)) throw InputError(where + ": '" + std::string(text) + "' is not a whole number");
  return v;
}

bool valid_name(std::string_view s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-')) return false;
  return true;
}

FaultClause parse_clause(std::string_view text, std::size_t index) {
  const std::size_t colon = text.find(':');
  const std::string_view kind_text = trim(text.substr(0, colon));
  const KindInfo* info = nullptr;
  for (const KindInfo& k : kKinds)
    if (kind_text == k.name) info = &k;
  const std::string at = "fault clause " + std::to_string(index);
  if (info == nullptr) {
    throw InputError(at + ": unknown fault '" + std::string(kind_text) +
                     "' (nan, flip, dup, replay, forge_seq, restart)");
  }
  const std::string where = at + " (" + info->name + ")";
  FaultClause c;
  c.kind = info->kind;
  std::set<std::string> seen;
  std::string_view rest = colon == std::string_view::npos ? std::string_view{} : text.substr(colon + 1);
  if (colon != std::string_view::npos && trim(rest).empty()) throw InputError(where + ": ':' without any key");
  while (!trim(rest).empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    if (comma != std::string_view::npos && trim(rest).empty()) throw InputError(where + ": trailing ','");
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) throw InputError(where + ": '" + std::string(item) + "' is not key=value");
    const std::string key(trim(item.substr(0, eq)));
    const std::string_view value = trim(item.substr(eq + 1));
    const std::string kw = where + " key '" + key + "'";
    if (!seen.insert(key).second) throw InputError(kw + ": given twice");
    const bool frame = is_frame_fault(c.kind);
    if (key == "at_s") {
      c.at_s = number_in(value, 0, 1e6, kw);
      c.once = true;
    } else if (key == "link" && frame) {
      if (!valid_name(value)) throw InputError(kw + ": '" + std::string(value) + "' is not a link name");
      c.link = value;
    } else if (key == "rate" && frame) {
      c.rate = number_in(value, 0, 1, kw);
    } else if (key == "bits" && c.kind == FaultClause::Kind::kFlip) {
      c.bits = static_cast<std::uint32_t>(integer_in(value, 1, 64, kw));
    } else if (key == "age_ms" && c.kind == FaultClause::Kind::kReplay) {
      c.age = Duration{std::llround(number_in(value, 1, 60000, kw) * 1e6)};
    } else if (key == "jump" && c.kind == FaultClause::Kind::kForgeSeq) {
      c.jump = static_cast<std::uint32_t>(integer_in(value, 1, 4294967295.0, kw));
    } else if (key == "node" && !frame) {
      if (!valid_name(value)) throw InputError(kw + ": '" + std::string(value) + "' is not a node name");
      c.node = value;
    } else {
      throw InputError(where + ": unknown key '" + key + "' (" + info->keys + ")");
    }
  }
  if (is_frame_fault(c.kind)) {
    if (!c.once && c.rate == 0) throw InputError(where + ": never fires (give rate > 0 or at_s)");
  } else {
    if (c.node.empty()) throw InputError(where + ": key 'node' is required");
    if (!c.once) throw InputError(where + ": key 'at_s' is required");
  }
  return c;
}

}  // namespace

const char* kind_name(FaultClause::Kind k) {
  for (const KindInfo& i : kKinds)
    if (i.kind == k) return i.name;
  return "?";
}

bool is_frame_fault(FaultClause::Kind k) { return k != FaultClause::Kind::kRestart; }

FaultSpec parse_fault_spec(std::string_view text) {
  FaultSpec spec;
  spec.text = std::string(trim(text));
  if (spec.text.empty()) return spec;
  std::string_view rest = spec.text;
  for (std::size_t index = 1;; ++index) {
    const std::size_t semi = rest.find(';');
    const std::string_view clause = trim(rest.substr(0, semi));
    if (clause.empty()) throw InputError("fault clause " + std::to_string(index) + ": empty (stray ';')");
    spec.clauses.push_back(parse_clause(clause, index));
    if (semi == std::string_view::npos) break;
    rest = rest.substr(semi + 1);
  }
  return spec;
}

std::string to_text(const FaultClause& c) {
  std::string s = kind_name(c.kind);
  char b[64];
  const auto add = [&](const std::string& kv) { s += (s.find(':') == std::string::npos ? ":" : ",") + kv; };
  if (!c.link.empty()) add("link=" + c.link);
  if (!c.node.empty()) add("node=" + c.node);
  if (is_frame_fault(c.kind) && c.rate > 0) {
    std::snprintf(b, sizeof b, "rate=%g", c.rate);
    add(b);
  }
  if (c.once) {
    std::snprintf(b, sizeof b, "at_s=%g", c.at_s);
    add(b);
  }
  if (c.kind == FaultClause::Kind::kFlip) add("bits=" + std::to_string(c.bits));
  if (c.kind == FaultClause::Kind::kReplay) {
    std::snprintf(b, sizeof b, "age_ms=%g", static_cast<double>(c.age.count()) * 1e-6);
    add(b);
  }
  if (c.kind == FaultClause::Kind::kForgeSeq) add("jump=" + std::to_string(c.jump));
  return s;
}

}  // namespace oneshot::engine
