/// @file jitter_model.cpp
/// @brief Jitter models.
#include "jitter_model.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "oneshot/util/file_io.hpp"

namespace oneshot::sim {

JobTiming JitterModel::draw(RandomStream& rng, std::size_t k) const {
  switch (kind) {
    case Kind::kNone:
      return {};
    case Kind::kUniform: {
      // Integer µs uniform on [min, max]; both draws always consumed (stream alignment).
      const double ur = rng.uniform01();
      const double ue = rng.uniform01();
      JobTiming t;
      t.release_us = release_min_us + static_cast<std::int32_t>(std::floor(ur * (release_max_us - release_min_us + 1)));
      t.exec_us = exec_min_us + static_cast<std::int32_t>(std::floor(ue * (exec_max_us - exec_min_us + 1)));
      return t;
    }
    case Kind::kTrace:
      return trace[k % trace.size()];
  }
  return {};
}

std::int32_t JitterModel::max_busy_us() const {
  switch (kind) {
    case Kind::kNone:
      return 0;
    case Kind::kUniform:
      return release_max_us + exec_max_us;
    case Kind::kTrace: {
      std::int32_t m = 0;
      for (const JobTiming& t : trace) m = std::max(m, t.release_us + t.exec_us);
      return m;
    }
  }
  return 0;
}

std::string JitterModel::describe() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::kNone:
      o << "none";
      break;
    case Kind::kUniform:
      o << "uniform release " << release_min_us / 1000.0 << "-" << release_max_us / 1000.0 << " ms, exec "
        << exec_min_us / 1000.0 << "-" << exec_max_us / 1000.0 << " ms";
      break;
    case Kind::kTrace:
      o << "trace " << trace_path << " (" << trace.size() << " jobs)";
      break;
  }
  return o.str();
}

namespace {
std::int32_t get_us(const nlohmann::json& j, const char* key, const std::string& field, std::int32_t fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_number_integer() || it->get<std::int64_t>() < 0 || it->get<std::int64_t>() > kMaxJobTimeUs) {
    throw ScenarioError("field '" + field + "." + key + "': must be an integer number of microseconds in [0, 6e7]");
  }
  return static_cast<std::int32_t>(it->get<std::int64_t>());
}
}  // namespace

JitterModel parse_jitter(const nlohmann::json& j, const std::string& field, const std::string& base_dir,
                         const TraceLoader& load_trace) {
  if (!j.is_object()) throw ScenarioError("field '" + field + "': must be an object");
  for (const auto& item : j.items()) {
    static const char* const kKnown[] = {"model", "release_min_us", "release_max_us", "exec_min_us", "exec_max_us",
                                         "file"};
    if (std::find(std::begin(kKnown), std::end(kKnown), item.key()) == std::end(kKnown)) {
      throw ScenarioError("field '" + field + "." + item.key() + "': unknown field");
    }
  }
  const auto model = j.find("model");
  if (model == j.end() || !model->is_string()) {
    throw ScenarioError("field '" + field + ".model': must be \"none\", \"uniform\" or \"trace\"");
  }
  JitterModel m;
  const std::string kind = model->get<std::string>();
  if (kind == "none") {
    m.kind = JitterModel::Kind::kNone;
  } else if (kind == "uniform") {
    m.kind = JitterModel::Kind::kUniform;
    m.release_min_us = get_us(j, "release_min_us", field, 0);
    m.release_max_us = get_us(j, "release_max_us", field, 0);
    m.exec_min_us = get_us(j, "exec_min_us", field, 0);
    m.exec_max_us = get_us(j, "exec_max_us", field, m.exec_min_us);
    if (m.release_max_us < m.release_min_us) throw ScenarioError("field '" + field + ".release_max_us': below release_min_us");
    if (m.exec_max_us < m.exec_min_us) throw ScenarioError("field '" + field + ".exec_max_us': below exec_min_us");
  } else if (kind == "trace") {
    m.kind = JitterModel::Kind::kTrace;
    const auto file = j.find("file");
    if (file == j.end() || !file->is_string()) throw ScenarioError("field '" + field + ".file': must name a CSV trace");
    std::filesystem::path path = file->get<std::string>();
    if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
    m.trace_path = path.string();
    m.trace = load_trace ? load_trace(m.trace_path) : load_jitter_trace(m.trace_path);
  } else {
    throw ScenarioError("field '" + field + ".model': unknown model '" + kind + "' (none, uniform, trace)");
  }
  return m;
}

namespace {

/// Spaces and tabs at both ends removed (and the CR of a CRLF line end).
std::string trimmed(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return line.substr(first, line.find_last_not_of(" \t\r") - first + 1);
}

/// A decimal integer in [0, kMaxJobTimeUs] filling all of `text` (after trimming), or −1.
std::int64_t job_time(const std::string& text) {
  const std::string t = trimmed(text);
  if (t.empty() || t.size() > 9) return -1;
  std::int64_t v = 0;
  for (char ch : t) {
    if (ch < '0' || ch > '9') return -1;
    v = v * 10 + (ch - '0');
  }
  return v <= kMaxJobTimeUs ? v : -1;
}

}  // namespace

std::vector<JobTiming> parse_jitter_trace(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || trimmed(line) != "release_us,exec_us") {
    throw ScenarioError(source + ": line 1: expected the header 'release_us,exec_us'");
  }
  std::vector<JobTiming> out;
  for (int n = 2; std::getline(in, line); ++n) {
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '#') continue;
    const auto comma = t.find(',');
    const std::int64_t r = comma == std::string::npos ? -1 : job_time(t.substr(0, comma));
    const std::int64_t e = comma == std::string::npos ? -1 : job_time(t.substr(comma + 1));
    if (r < 0 || e < 0) {
      throw ScenarioError(source + ": line " + std::to_string(n) +
                          ": expected 'release_us,exec_us': two integers in [0, 60000000] and nothing else, got '" +
                          t.substr(0, 80) + "'");
    }
    out.push_back({static_cast<std::int32_t>(r), static_cast<std::int32_t>(e)});
  }
  if (out.empty()) throw ScenarioError(source + ": the trace has no jobs");
  return out;
}

std::vector<JobTiming> load_jitter_trace(const std::string& path) {
  return parse_jitter_trace(util::read_text_file_as<ScenarioError>(path, "jitter trace"), path);
}

}  // namespace oneshot::sim
