/// @file study_ncs_scenario_map.cpp
/// @brief A study file's scenario mapped onto an ncs Scenario, and the reference approach's cost
///        on it (see study_ncs_scenario_map.hpp).
#include "study_ncs_scenario_map.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "study_fields.hpp"

namespace oneshot::study {

using engine::InputError;

std::string zero_reference_cost(const ncs::Context& ctx, const ncs::Scenario& sc, ncs::Approach leading) {
  // IK (no delay, Kalman) runs the plant's process noise Q_c · noise_scale: it costs more than 0 while that is not 0.
  if (leading != ncs::Approach::kI && sc.noise_scale != 0) return "";
  const std::string who = std::string("the reference approach ") + ncs::name(leading);
  const std::string noiseless = leading == ncs::Approach::kI ? "" : " (noise_scale 0)";
  const std::uint64_t k = ncs::first_setpoint_change(ctx, sc);
  if (k == 0) {
    return sc.setpoint_changes ? "the set-point never changes, so " + who + noiseless + " costs 0: no ratio to it"
                               : "amplitude 0 keeps " + who + noiseless + " at cost 0: no ratio to it";
  }
  const double first_switch_s = static_cast<double>(k) * static_cast<double>(ctx.period_us()) * 1e-6;
  if (!(sc.duration_s > first_switch_s)) {
    return "the run ends (" + std::to_string(sc.duration_s) + " s) before the first set-point switch at " +
           std::string(sc.setpoint_changes ? "" : "T_r/2 = ") + std::to_string(first_switch_s) + " s, so " + who + noiseless +
           " costs 0: no ratio to it";
  }
  return "";
}

ncs::Scenario map_ncs_scenario(const engine::StudyFile& file, std::size_t i, const NcsStudy& study, const NcsScenarioInputs& in) {
  const std::int64_t h_us = study.ctx->period_us();
  const engine::ScenarioSpec& s = file.scenarios[i];
  const std::string f = at("scenarios", i);
  // The set-point: the scenario's `reference`, else the file's, else the square wave of the
  // params amplitude_volts and period_s (required then, refused with a reference).
  const engine::ReferenceSpec* ref = s.reference ? &*s.reference : (file.reference ? &*file.reference : nullptr);
  // The schema's checks again, on what the file gave (a file parsed without it reaches here too).
  std::map<std::string, double> params;
  for (const auto& [key, v] : s.params) {
    if (s.params_given.count(key) == 0) continue;  // a schema default
    const engine::ParamSpec* spec = nullptr;
    for (const engine::ParamSpec& p : ncs_schema().scenario_params)
      if (p.name == key) spec = &p;
    if (spec == nullptr) refuse(f + ".params", "unknown parameter (amplitude_volts, period_s, noise_scale)");
    if (!(v >= spec->min && v <= spec->max)) refuse(f + ".params." + key, "out of range");
    params[key] = v;
  }
  for (const engine::ParamSpec& p : ncs_schema().scenario_params) {
    const std::string g = f + ".params." + p.name;
    const bool wave = p.name == "amplitude_volts" || p.name == "period_s";
    if (wave && ref != nullptr && params.count(p.name) != 0) {
      refuse(g, "the set-point comes from '" + ref->field + "' (a square wave there takes amplitude_volts and period_s)");
    }
    if (params.count(p.name) != 0) continue;
    if (wave && ref == nullptr) refuse(g, "missing (or give the set-point as a 'reference')");
    params[p.name] = p.fallback;
  }
  ncs::Scenario sc;
  sc.name = s.name;
  sc.amplitude_volts = params.at("amplitude_volts");
  sc.period_s = params.at("period_s");
  sc.noise_scale = params.at("noise_scale");
  std::string amplitude_field = f + ".params.amplitude_volts";
  std::string period_field = f + ".params.period_s";
  if (ref != nullptr && ref->kind == engine::ReferenceSpec::Kind::kSquare) {  // the params' square wave, bit for bit
    sc.amplitude_volts = ref->amplitude_volts;
    sc.period_s = ref->period_s;
    amplitude_field = ref->field + ".amplitude_volts";
    period_field = ref->field + ".period_s";
  } else if (ref != nullptr) {
    sc.amplitude_volts = 0;
    sc.period_s = 0;
    amplitude_field = ref->field + (ref->kind == engine::ReferenceSpec::Kind::kFile ? ".path" : ".steps");
    try {
      ncs::set_steps(sc, h_us, ref->steps, ref->lines, ref->path);
    } catch (const std::invalid_argument& e) {
      refuse(amplitude_field, e.what());
    }
    sc.setpoint_description = ref->describe();
  }
  sc.duration_s = s.duration_s.value_or(file.duration_s);
  sc.sod_delta = in.sod_delta;
  sc.sod_time_steps = in.sod_time_steps;
  if (in.mtm_rule) {
    sc.sensor_mtm = true;
    sc.mtm_sigma = in.mtm_rule->sigma;
    sc.mtm_delta = in.mtm_rule->mtm_delta;
    sc.mtm_k_max = in.mtm_rule->k_max;
    sc.mtm_k_ref_max = in.mtm_rule->k_ref_max;
  }
  sc.controller_phase_us = in.phase_us;
  for (const engine::LinkSpec& l : file.links) {
    if (l.bus.empty()) {
      sc.legs[l.name] = file.link_config(l.name, &s);
      continue;
    }
    ncs::BusLeg b;
    for (const engine::BusSpec& bus : file.buses) {
      if (bus.config.name != l.bus) continue;
      b.bus = bus.config;
      b.background = bus.background;
      b.offsets = bus.offsets;
    }
    b.id = l.id;
    sc.bus_legs[l.name] = b;
  }
  // d of study ncs (every leg U[0.5, d] ms) has no meaning for the file's legs, and ncs::run
  // takes the legs instead: 0. study run leaves ncs table's by-d keys out and reports each
  // scenario's sc + ca delay bound (study_ncs_sweep.hpp).
  sc.max_delay_ms = 0;
  if (!sc.setpoint_changes) {
    try {
      static_cast<void>(ncs::half_wave_periods(*study.ctx, sc));
    } catch (const std::exception&) {
      refuse(period_field, "T_r/2 must be a whole number of periods h = " + std::to_string(h_us) + " us");
    }
  }
  if (!(sc.duration_s * 1e6 >= static_cast<double>(h_us))) refuse(f + ".duration_s", "shorter than one period h");
  const ncs::Approach leading = study.approaches.empty() ? ncs::Approach::kI : study.approaches[0];  // the ratios' reference
  const std::string zero = zero_reference_cost(*study.ctx, sc, leading);
  if (!zero.empty() && ncs::first_setpoint_change(*study.ctx, sc) == 0) refuse(amplitude_field, zero);
  if (!zero.empty()) refuse(s.duration_s ? f + ".duration_s" : std::string("duration_s"), zero);
  for (ncs::Approach a : study.approaches) {
    const std::string g = f + " with approach " + ncs::name(a);
    if (a == ncs::Approach::kSPlus) {
      const double tau = study.ctx->mean_tau_io_us(sc);
      if (!(tau < static_cast<double>(h_us))) {
        refuse(g, "S+ designs on the mean delay tau_io = " + std::to_string(tau) + " us, which must be below h");
      }
      try {
        static_cast<void>(ncs::delay_compensated_split(*study.ctx, tau));
      } catch (const std::exception& e) {
        refuse(g, e.what());
      }
    }
    if (a == ncs::Approach::kAKl) {
      try {
        static_cast<void>(study.ctx->worst_chain_us(sc));
      } catch (const std::exception& e) {
        refuse(g, e.what());
      }
    }
  }
  sc.one_shot_triples = in.one_shot_triples;
  return sc;
}

// Declared with the runner (study_ncs_runner.hpp): the scenarios capped, each checked as mapped.
void cap_duration(NcsStudy& s, double max_s, const std::string& field) {
  if (!s.loops.empty()) {  // every loop (the same scenarios), then this study's fields: the first loop's
    std::vector<NcsStudy> loops = s.loops;
    for (NcsStudy& l : loops) cap_duration(l, max_s, field);
    s.scenarios = loops[0].scenarios;
    s.loops = std::move(loops);
    return;
  }
  const double h_s = static_cast<double>(s.ctx->period_us()) * 1e-6;
  if (!(std::isfinite(max_s) && max_s >= h_s)) {
    throw InputError("field '" + field + "': " + std::to_string(max_s) + " s is shorter than one period h = " +
                     std::to_string(h_s) + " s");
  }
  std::vector<ncs::Scenario> capped = s.scenarios;  // `s` unchanged when a scenario is refused
  for (ncs::Scenario& x : capped) {
    x.duration_s = std::fmin(x.duration_s, max_s);
    const std::string zero = zero_reference_cost(*s.ctx, x, s.approaches.empty() ? ncs::Approach::kI : s.approaches[0]);
    if (!zero.empty()) throw InputError("field '" + field + "': scenario " + x.name + ": " + zero);
  }
  s.scenarios = std::move(capped);
}

}  // namespace oneshot::study
