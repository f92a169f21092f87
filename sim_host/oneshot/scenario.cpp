/// @file scenario.cpp
/// @brief Scenarios.
#include "scenario.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "oneshot/util/file_io.hpp"
#include "oneshot/util/strict_json.hpp"

namespace oneshot::sim {
namespace {

double number(const nlohmann::json& j, const char* key, const std::string& field, double fallback, double lo,
              double hi) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_number() || !(it->get<double>() >= lo && it->get<double>() <= hi)) {
    std::ostringstream o;
    o << "field '" << field << "." << key << "': must be a number in [" << lo << ", " << hi << "]";
    throw ScenarioError(o.str());
  }
  return it->get<double>();
}

}  // namespace

Scenario uniform_scenario(const std::string& name, std::int32_t jitter_us, double amplitude_volts,
                          double change_period_s, double duration_s) {
  Scenario s;
  s.name = name;
  s.duration_s = duration_s;
  s.amplitude_volts = amplitude_volts;
  s.change_period_s = change_period_s;
  s.jitter.kind = JitterModel::Kind::kUniform;
  s.jitter.release_min_us = 0;
  s.jitter.release_max_us = jitter_us;
  s.jitter.exec_min_us = 200;
  s.jitter.exec_max_us = 600;
  return s;
}

std::vector<Scenario> default_scenarios() {
  // The brief's protocol: sampling jitter within 0–20 ms; set-point amplitudes from the
  // ±0.2 V demonstration up to 1 V; change periods 0.5–2 s (docs/oneshot.md, "Scenarios").
  return {
      uniform_scenario("j5-a0.2-p1", 5'000, 0.2, 1.0),
      uniform_scenario("j10-a0.2-p1", 10'000, 0.2, 1.0),
      uniform_scenario("j15-a0.2-p1", 15'000, 0.2, 1.0),
      uniform_scenario("j20-a0.2-p1", 20'000, 0.2, 1.0),
      uniform_scenario("j20-a0.5-p1", 20'000, 0.5, 1.0),
      uniform_scenario("j20-a1.0-p1", 20'000, 1.0, 1.0),
      uniform_scenario("j20-a0.2-p0.5", 20'000, 0.2, 0.5),
      uniform_scenario("j20-a0.2-p2", 20'000, 0.2, 2.0),
      uniform_scenario("j10-a0.5-p0.5", 10'000, 0.5, 0.5),
      uniform_scenario("j15-a1.0-p2", 15'000, 1.0, 2.0),
  };
}

Scenario find_scenario(const std::vector<Scenario>& scenarios, const std::string& name) {
  for (const Scenario& s : scenarios) {
    if (s.name == name) return s;
  }
  std::string names;
  for (const Scenario& s : scenarios) names += (names.empty() ? "" : ", ") + s.name;
  throw ScenarioError("unknown scenario '" + name + "' (available: " + names + ")");
}

std::vector<Scenario> parse_scenarios(const std::string& text, const std::string& source, const std::string& base,
                                      const TraceLoader& load_trace) {
  nlohmann::json root;
  try {
    root = util::parse_json_strict(text);
  } catch (const util::JsonError& e) {
    throw ScenarioError(source + ": " + e.what());
  }
  try {
    if (!root.is_object() || !root.contains("scenarios") || !root["scenarios"].is_array() || root["scenarios"].empty()) {
      throw ScenarioError("field 'scenarios': must be a non-empty array");
    }
    for (const auto& item : root.items()) {
      if (item.key() != "scenarios") throw ScenarioError("field '" + item.key() + "': unknown field");
    }
    std::vector<Scenario> out;
    std::map<std::string, std::size_t> names;
    for (std::size_t i = 0; i < root["scenarios"].size(); ++i) {
      const nlohmann::json& j = root["scenarios"][i];
      const std::string field = "scenarios[" + std::to_string(i) + "]";
      if (!j.is_object()) throw ScenarioError("field '" + field + "': must be an object");
      for (const auto& item : j.items()) {
        if (item.key() != "name" && item.key() != "duration_s" && item.key() != "setpoint" && item.key() != "jitter") {
          throw ScenarioError("field '" + field + "." + item.key() + "': unknown field");
        }
      }
      Scenario s;
      const auto name = j.find("name");
      if (name == j.end() || !name->is_string() || name->get<std::string>().empty() || name->get<std::string>().size() > 100) {
        throw ScenarioError("field '" + field + ".name': must be a string of 1 to 100 characters");
      }
      s.name = name->get<std::string>();
      if (std::any_of(s.name.begin(), s.name.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; })) {
        throw ScenarioError("field '" + field + ".name': control characters (line breaks, tabs) are not allowed: the "
                            "name appears in tables and plot titles");
      }
      const auto [seen, fresh] = names.emplace(s.name, i);
      if (!fresh) {
        throw ScenarioError("field '" + field + ".name': '" + s.name + "' is already the name of scenarios[" +
                            std::to_string(seen->second) + "] (names select scenarios: they must be unique)");
      }
      s.duration_s = number(j, "duration_s", field, 20.0, 0.05, 1e5);
      if (j.contains("setpoint")) {
        const nlohmann::json& sp = j["setpoint"];
        if (!sp.is_object()) throw ScenarioError("field '" + field + ".setpoint': must be an object");
        for (const auto& item : sp.items()) {
          if (item.key() != "amplitude_volts" && item.key() != "change_period_s") {
            throw ScenarioError("field '" + field + ".setpoint." + item.key() + "': unknown field");
          }
        }
        s.amplitude_volts = number(sp, "amplitude_volts", field + ".setpoint", 0.2, 0.0, 1e3);
        s.change_period_s = number(sp, "change_period_s", field + ".setpoint", 1.0, 1e-3, 1e5);
      }
      if (j.contains("jitter")) s.jitter = parse_jitter(j["jitter"], field + ".jitter", base, load_trace);
      out.push_back(s);
    }
    return out;
  } catch (const ScenarioError& e) {
    throw ScenarioError(source + ": " + e.what());
  }
}

std::vector<Scenario> load_scenarios(const std::string& path) {
  const std::string text = util::read_text_file_as<ScenarioError>(path, "scenario file");
  return parse_scenarios(text, path, std::filesystem::path(path).parent_path().string());
}

void validate_scenario(const Scenario& s, const design::PlantDescription& plant) {
  const std::int32_t busy = s.jitter.max_busy_us();
  if (busy >= plant.period_us) {
    throw ScenarioError("scenario '" + s.name + "': release + execution can reach " + std::to_string(busy) +
                        " us, not below the period of " + std::to_string(plant.period_us) +
                        " us (the job would overrun its actuation instant)");
  }
  for (std::size_t o = 0; o < plant.p(); ++o) {
    if (s.amplitude_volts >= plant.board.adc_max_volts[o] || -s.amplitude_volts <= plant.board.adc_min_volts[o]) {
      throw ScenarioError("scenario '" + s.name + "': set-point amplitude is outside the ADC range");
    }
  }
  if (s.duration_s * 1e6 < plant.period_us) throw ScenarioError("scenario '" + s.name + "': shorter than one period");
  if (s.duration_s / s.change_period_s > kMaxSetpointChanges) {
    throw ScenarioError("scenario '" + s.name + "': " + std::to_string(s.duration_s / s.change_period_s) +
                        " set-point changes in one run, more than the limit of 10^7 (a change period of " +
                        std::to_string(s.change_period_s) + " s over " + std::to_string(s.duration_s) + " s)");
  }
}

std::int32_t SetpointSchedule::code_at(std::int64_t t_ns) const {
  const auto it = std::upper_bound(at_ns.begin(), at_ns.end(), t_ns);
  return it == at_ns.begin() ? code.front() : code[static_cast<std::size_t>(it - at_ns.begin()) - 1];
}

SetpointSchedule make_schedule(const Scenario& s, const design::PlantDescription& plant, std::uint64_t seed) {
  RandomStream rng(seed, "setpoint");
  SetpointSchedule sch;
  const double lsb = (plant.board.adc_max_volts[0] - plant.board.adc_min_volts[0]) / std::ldexp(1.0, plant.board.adc_bits);
  const std::int64_t step = std::llround(s.change_period_s * 1e9);
  const std::int64_t end = std::llround(s.duration_s * 1e9);
  for (std::int64_t t = 0; t <= end; t += step) {
    // The circuit starts at rest: reference 0 V until the first change.
    const double v = t == 0 ? 0.0 : rng.uniform(-s.amplitude_volts, s.amplitude_volts);
    // Nearest code whose bin centre (the sensor model's value) is v.
    const double code = std::floor((v - plant.board.adc_min_volts[0]) / lsb);
    sch.at_ns.push_back(t);
    sch.code.push_back(static_cast<std::int32_t>(code));
  }
  return sch;
}

}  // namespace oneshot::sim
