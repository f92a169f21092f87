/// @file study_reference.cpp
/// @brief The "reference" section of a study file: a square wave, steps, or steps from a CSV
///        file (see study_file.hpp and docs/study-files.md).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/util/file_io.hpp"

namespace oneshot::engine {
namespace {

constexpr double kMaxReferenceVolts = 100;   ///< |value| bound, as the square wave's amplitude.
constexpr double kMaxReferenceTimeS = 1e6;   ///< Latest step time, as the longest run.
constexpr std::size_t kMaxReferenceFileBytes = std::size_t{1} << 23;  ///< 8 MiB.

/// `text` (spaces around it allowed) as a finite double; false when it is not exactly one.
bool parse_number(std::string text, double& out) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.pop_back();
  std::size_t b = 0;
  while (b < text.size() && (text[b] == ' ' || text[b] == '\t')) ++b;
  text = text.substr(b);
  if (text.empty() || text.size() > 64) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE) return false;
  out = v;
  return std::isfinite(v);
}

/// Checks step `t, v` after `prev` (the steps so far): "" when it is valid, else the reason.
std::string step_error(const std::vector<std::pair<double, double>>& prev, double t, double v) {
  if (!(t >= 0 && t <= kMaxReferenceTimeS)) return "t_s must be finite in [0, 1e6] s";
  if (!(std::fabs(v) <= kMaxReferenceVolts)) return "value_volts must be finite in [-100, 100] V";
  if (!prev.empty() && !(t > prev.back().first)) return "times must increase strictly";
  if (prev.size() >= kMaxReferenceSteps) return "more than " + std::to_string(kMaxReferenceSteps) + " steps";
  return "";
}

}  // namespace

std::string ReferenceSpec::describe() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::kSquare:
      o << "square +-" << amplitude_volts << " V, T_r " << period_s << " s";
      break;
    case Kind::kSteps:
      o << "steps (" << steps.size() << ")";
      break;
    case Kind::kFile:
      o << "file " << path << " (" << steps.size() << " steps)";
      break;
  }
  return o.str();
}

std::vector<std::pair<double, double>> parse_reference_csv(const std::string& text, const std::string& field,
                                                           const std::string& source, std::vector<std::size_t>* lines) {
  if (lines != nullptr) lines->clear();
  std::istringstream in(text);
  std::string line;
  const auto fail = [&](int n, const std::string& why) {
    throw InputError("field '" + field + "': " + source + " line " + std::to_string(n) + ": " + why);
  };
  if (!std::getline(in, line)) fail(1, "expected the header 't_s,value_volts'");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte-order mark (spreadsheets write one)
  if (line != "t_s,value_volts") fail(1, "expected the header 't_s,value_volts'");
  std::vector<std::pair<double, double>> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::size_t comma = line.find(',');
    double t = 0, v = 0;
    if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos ||
        !parse_number(line.substr(0, comma), t) || !parse_number(line.substr(comma + 1), v)) {
      fail(n, "expected two finite numbers 't_s,value_volts'");
    }
    const std::string why = step_error(out, t, v);
    if (!why.empty()) fail(n, why);
    out.emplace_back(t, v);
    if (lines != nullptr) lines->push_back(static_cast<std::size_t>(n));
  }
  if (out.empty()) throw InputError("field '" + field + "': " + source + ": no steps after the header");
  return out;
}

ReferenceSpec parse_reference(const nlohmann::json& j, const std::string& f, const std::string& base_dir) {
  ReferenceSpec r;
  r.field = f;
  const std::string kind = string_of(j, f, "kind");
  if (kind == "square") {
    require_keys(j, f, {"kind", "amplitude_volts", "period_s"});
    r.kind = ReferenceSpec::Kind::kSquare;
    r.amplitude_volts = number_in(j, f, "amplitude_volts", 0, kMaxReferenceVolts);
    r.period_s = number_in(j, f, "period_s", 1e-3, kMaxReferenceTimeS);
  } else if (kind == "steps") {
    require_keys(j, f, {"kind", "steps"});
    r.kind = ReferenceSpec::Kind::kSteps;
    const nlohmann::json& s = member(j, f, "steps");
    if (!s.is_array() || s.empty()) throw InputError("field '" + f + ".steps': must be a non-empty array of [t_s, value_volts]");
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::string g = f + ".steps[" + std::to_string(i) + "]";
      if (!s[i].is_array() || s[i].size() != 2 || !s[i][0].is_number() || !s[i][1].is_number()) {
        throw InputError("field '" + g + "': must be a pair [t_s, value_volts]");
      }
      const double t = s[i][0].get<double>();
      const double v = s[i][1].get<double>();
      const std::string why = step_error(r.steps, t, v);
      if (!why.empty()) throw InputError("field '" + g + "': " + why);
      r.steps.emplace_back(t, v);
    }
  } else if (kind == "file") {
    require_keys(j, f, {"kind", "path"});
    r.kind = ReferenceSpec::Kind::kFile;
    std::filesystem::path path = string_of(j, f, "path");
    if (path.empty()) throw InputError("field '" + f + ".path': must not be empty");
    if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
    r.path = path.lexically_normal().string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      throw InputError("field '" + f + ".path': " + r.path + " is not a readable regular file");
    }
    const std::string text =
        util::read_text_file_as<InputError>(r.path, "reference file", "field '" + f + ".path': ", kMaxReferenceFileBytes);
    r.steps = parse_reference_csv(text, f + ".path", r.path, &r.lines);
  } else {
    throw InputError("field '" + f + ".kind': unknown kind '" + kind + "' (square, steps, file)");
  }
  return r;
}

}  // namespace oneshot::engine
