/// @file scenario.hpp
/// @brief Experiment scenarios: duration, set-point profile and jitter.
///
/// The circuit starts at rest with reference 0 V; set-points then change every
/// `change_period_s` to a value drawn uniformly in [−amplitude, +amplitude] and rounded
/// to an ADC code, so that the controller and the
/// cost see the same reference. The reference is a known trajectory: a job asks for the
/// value valid when its output will be applied.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/design/plant_description.hpp"
#include "jitter_model.hpp"

namespace oneshot::sim {

/// One scenario.
struct Scenario {
  std::string name;                   ///< Identifier.
  double duration_s = 20;             ///< Simulated time per run.
  double amplitude_volts = 0.2;       ///< Set-points within ±amplitude.
  double change_period_s = 1.0;       ///< Time between set-point changes.
  JitterModel jitter;                 ///< Job timing.
};

/// A scenario with uniform release jitter 0..jitter_us and a 0.2-0.6 ms job (a Kalman job
/// on a 40-MIPS dsPIC), set-points within ±amplitude_volts changed every change_period_s.
Scenario uniform_scenario(const std::string& name, std::int32_t jitter_us, double amplitude_volts,
                          double change_period_s, double duration_s = 20.0);

/// The ten scenarios of Table I (documented in docs/oneshot.md).
std::vector<Scenario> default_scenarios();

/// The scenario called `name` in `scenarios` (ScenarioError listing the names otherwise).
Scenario find_scenario(const std::vector<Scenario>& scenarios, const std::string& name);

/// Parses {"scenarios": [{"name", "duration_s", "setpoint": {"amplitude_volts",
/// "change_period_s"}, "jitter": {...}}, ...]} (ScenarioError naming the field): strict
/// JSON (a key twice is refused), names unique, printable and at most 100 characters.
/// `source` names the text in errors; trace files are found from `base_dir`.
std::vector<Scenario> parse_scenarios(const std::string& text, const std::string& source, const std::string& base_dir,
                                      const TraceLoader& load_trace = {});

/// Reads (bounded) and parses a scenario file.
std::vector<Scenario> load_scenarios(const std::string& path);

/// Most set-point changes in one run (each is stored): 10^7.
inline constexpr double kMaxSetpointChanges = 1e7;

/// Checks a scenario against a plant: the job must finish within the period
/// (release + exec < h), set-points within the ADC range, at least one period long, at
/// most kMaxSetpointChanges set-point changes (ScenarioError).
void validate_scenario(const Scenario& s, const design::PlantDescription& plant);

/// Set-point code schedule: (time, ADC code) pairs, first at t = 0.
struct SetpointSchedule {
  std::vector<std::int64_t> at_ns;   ///< Change instants.
  std::vector<std::int32_t> code;    ///< ADC code from that instant.
  /// Code valid at time t (ns).
  std::int32_t code_at(std::int64_t t_ns) const;
};

/// Draws the schedule of scenario `s` for `seed` on output channel 0 of `plant`.
SetpointSchedule make_schedule(const Scenario& s, const design::PlantDescription& plant, std::uint64_t seed);

}  // namespace oneshot::sim
