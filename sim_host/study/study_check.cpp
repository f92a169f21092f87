/// @file study_check.cpp
/// @brief A study file resolved into its designs, link summaries and CAN bounds (see
///        study_check.hpp).
#include "study_check.hpp"

#include <cmath>
#include <algorithm>
#include <map>
#include <optional>
#include <sstream>

#include "ncs_model.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/zoh_inverse.hpp"
#include "study_bus_analysis.hpp"
#include "study_cpu.hpp"
#include "study_ncs_runner.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {
namespace {

using engine::InputError;
using nlohmann::json;

json rows(const design::DenseMatrix& m) {
  json out = json::array();
  for (std::size_t i = 0; i < m.rows; ++i) {
    json r = json::array();
    for (std::size_t j = 0; j < m.cols; ++j) r.push_back(m(i, j));
    out.push_back(r);
  }
  return out;
}

json delay_summary(const engine::DelayModel& d) {
  json j = {{"model", d.describe()}, {"min_us", to_us(d.lower_bound())}, {"mean_us", d.mean_ns() * 1e-3}};
  const auto ub = d.upper_bound();
  if (ub) {
    j["max_us"] = to_us(*ub);
  } else {
    j["max_us"] = nullptr;
    // Only the heavy tails are capped (draws above the cap are clamped); Poisson is not.
    if (d.kind == engine::DelayModel::Kind::kLognormal || d.kind == engine::DelayModel::Kind::kPareto) j["cap_us"] = to_us(d.cap);
  }
  return j;
}

json link_summary(const engine::LinkConfig& c) {
  return {{"delay", delay_summary(c.delay)},
          {"loss", c.loss.describe()},
          {"loss_probability", c.loss.loss_rate()},
          {"order", c.fifo ? "fifo" : "any"}};
}

bool one_shot_kind(const std::string& kind) {
  for (ncs::Approach k : ncs::kOneShotApproaches)
    if (kind == ncs::name(k)) return true;
  return false;
}

bool has_estimator(const std::string& kind) {
  return kind == "AK" || kind == "AKx" || kind == "AKl" || kind == "SK" || kind == "IK" || one_shot_kind(kind);
}

bool ncs_kind(const std::string& kind) {
  for (ncs::Approach a : ncs::kAllApproaches)
    if (kind == ncs::name(a)) return true;
  return one_shot_kind(kind);
}

json plant_section(const engine::StudyFile& f, json& designs) {
  json j;
  std::string field = "plant";  // what a design error names
  design::PlantDescription p;
  switch (f.plant.kind) {
    case engine::PlantSpec::Kind::kContinuous:
      if (!f.plant.design) {
        j = {{"kind", "continuous"}, {"n", f.plant.continuous.a.rows}, {"m", f.plant.continuous.b.cols},
             {"p", f.plant.continuous.c.rows}, {"designed", false},
             {"why_not_designed", "no design keys: give period_us and measurement_covariance (and Q1c, Q2c, actuator or board)"}};
        return j;
      }
      p = *f.plant.design;
      field = "plant.continuous";
      if (p.cost_form == design::CostForm::kNone) {
        throw InputError("field 'plant.continuous.Q1c': missing: no LQR gain without Q1c and Q2c");
      }
      break;
    case engine::PlantSpec::Kind::kDiscrete:
      if (!f.plant.design) {
        j = {{"kind", "discrete"}, {"n", f.plant.discrete.phi.rows}, {"m", f.plant.discrete.gamma.cols},
             {"p", f.plant.discrete.c.rows}, {"period_us", to_us(f.plant.discrete.period)}, {"designed", false},
             {"why_not_designed", "no design keys: give measurement_covariance, Q1c, Q2c and a board (the plant then runs as "
                                  "its exact continuous equivalent)"}};
        return j;
      }
      p = *f.plant.design;
      field = "plant.discrete";
      if (p.cost_form == design::CostForm::kNone) {
        throw InputError("field 'plant.discrete.Q1c': missing: no LQR gain without Q1c and Q2c");
      }
      break;
    case engine::PlantSpec::Kind::kFile: {
      const std::string path = plant_file_path(f);
      try {
        p = design::load_plant_file(path);
      } catch (const std::exception& e) {
        throw InputError("field 'plant.file': " + std::string(e.what()));
      }
      break;
    }
  }
  design::DesignResult d;
  try {
    d = design::synthesize(p);
  } catch (const std::exception& e) {
    throw InputError("field '" + field + "': " + std::string(e.what()));
  }
  if (!d.lqr_available) throw InputError("field '" + field + "': no LQR gain: " + d.lqr_unavailable_reason);
  if (f.plant.kind == engine::PlantSpec::Kind::kFile) {
    j = {{"kind", "file"}, {"file", p.source}};
  } else {
    j = {{"kind", f.plant.kind == engine::PlantSpec::Kind::kDiscrete ? "discrete" : "continuous"}};
  }
  j.update({{"name", p.name}, {"form", design::to_string(p.form)}, {"n", p.n()}, {"m", p.m()}, {"p", p.p()},
            {"period_us", p.period_us}, {"designed", true}});
  if (f.study == "ncs") {  // the shape the ncs loops run it on (ncs_model.hpp): its own, or a larger one zero padded
    const ncs::NcsShapeOf on = ncs::ncs_shape_of(p.n(), p.m(), p.p());
    if (on.n != 0) {
      j["runs_on_shape"] = {{"n", on.n}, {"m", on.m}, {"p", on.p}, {"padded", on.padded}};
    }
  }
  if (p.from_discrete) {  // the exact continuous equivalent the loop runs (design::zoh_inverse)
    j["continuous_equivalent"] = {{"A", rows(p.a)},
                                  {"B", rows(p.b)},
                                  {"Q_c", rows(p.process_intensity)},
                                  {"reconstruction_relative_error", p.d2c_relative_error},
                                  {"noise_relative_error", p.d2c_noise_relative_error}};
    if (!(p.d2c_phi_condition <= design::kZohInverseWarnCondition)) {  // warned, not refused: the backward check passed
      std::ostringstream w;
      w.precision(3);
      w << "Phi is near-singular (condition estimate " << p.d2c_phi_condition << " above " << design::kZohInverseWarnCondition
        << "): the recovered A is ill-conditioned (trust it to about " << p.d2c_phi_condition * 1.1e-16 << " relative)";
      j["continuous_equivalent"]["phi_condition"] = p.d2c_phi_condition;
      j["continuous_equivalent"]["warning"] = w.str();
    }
  }
  designs["lqr_gain"] = rows(d.l);
  designs["closed_loop_spectral_radius"] = d.closed_loop_radius;
  designs["kalman_gain"] = rows(d.kalman_gain);
  designs["estimator_spectral_radius"] = d.estimator_radius;
  return j;
}

}  // namespace

json resolve_study(const engine::StudyFile& f) {
  if (!f.loops.empty()) {  // per loop its plant and designs; the links and the buses of the whole file
    json r;
    for (std::size_t i = 0; i < f.loops.size(); ++i) {
      engine::StudyFile v = loop_view(f, i);
      v.buses.clear();
      for (engine::LinkSpec& l : v.links) l.bus.clear();  // analysed below, with every loop's traffic
      json ri;
      try {
        ri = resolve_study(v);
      } catch (const InputError& e) {  // the loop's plant: named loops[i].plant
        std::string what = e.what();
        const std::string prefix = f.source + ": field 'plant";
        if (what.rfind(prefix, 0) == 0) what.replace(0, prefix.size(), f.source + ": field 'loops[" + std::to_string(i) + "].plant");
        throw InputError(what);
      }
      if (i == 0) r = ri;
      const engine::LoopSpec& l = f.loops[i];
      r["loops"].push_back({{"name", l.name}, {"sensor", l.sensor}, {"controller", l.controller}, {"actuator", l.actuator},
                            {"plant", ri.at("plant")}, {"approaches", ri.at("approaches")}});
      const engine::Duration phase = f.node(l.sensor).clock_offset;  // the loop's phase (only then: the rest stays as it was)
      if (phase.count() != 0) r["loops"].back()["clock_offset_us"] = static_cast<double>(phase.count()) * 1e-3;
    }
    try {
      r["links"] = json::array();
      for (const engine::LinkSpec& l : f.links) {
        json e = {{"name", l.name}, {"from", l.from}, {"to", l.to}};
        if (l.bus.empty()) {
          e["base"] = link_summary(f.link_config(l.name));
          for (const engine::ScenarioSpec& s : f.scenarios)
            if (s.delays.count(l.name) != 0 || s.losses.count(l.name) != 0) e["scenarios"][s.name] = link_summary(f.link_config(l.name, &s));
        } else {
          e["bus"] = l.bus;
          e["id"] = l.id;
        }
        r["links"].push_back(e);
      }
      r.erase("buses");
      if (!f.buses.empty()) r["buses"] = analyze_buses(f);
      r["source"] = f.source;
    } catch (const InputError& e) {
      throw InputError(f.source + ": " + e.what());
    }
    return r;
  }
  try {
    json r;
    r["source"] = f.source;
    r["study"] = f.study;
    r["duration_s"] = f.duration_s;
    r["seeds"] = {{"first", f.first_seed}, {"count", f.seeds}};
    json design = json::object();
    r["plant"] = plant_section(f, design);
    const bool designed = r["plant"].at("designed").get<bool>();
    // Per approach: the design its kind implies.
    std::shared_ptr<const ncs::Context> ctx;
    for (const engine::ApproachSpec& a : f.approaches) {
      json e = {{"name", a.name}, {"kind", a.kind}, {"params", a.params}};
      for (const auto& [key, word] : a.words) e["params"][key] = word;  // word parameters (discretizer)
      if (!designed) {
        e["design"] = "none (plant not designed)";
      } else if (f.study != "ncs" || !ncs_kind(a.kind)) {
        e["design"] = "LQR (the kind is not an ncs approach: no estimator assumed)";
        e["lqr_gain"] = design["lqr_gain"];
        e["closed_loop_spectral_radius"] = design["closed_loop_spectral_radius"];
      } else {
        e["lqr_gain"] = design["lqr_gain"];
        e["closed_loop_spectral_radius"] = design["closed_loop_spectral_radius"];
        e["design"] = has_estimator(a.kind) ? "LQR + Kalman" : "LQR";
        if (one_shot_kind(a.kind)) {  // the filter runs on what arrives: its gain varies (kalman_gain: the steady state of every sample)
          e["design"] = a.kind == "OS" ? "LQR on the prediction to (k+1)h + Kalman filter, a silent sensor's held value with inflated R"
                                       : "LQR on the prediction to (k+1)h + Kalman filter, predict-only when no sample arrives";
        }
        if (has_estimator(a.kind)) {
          e["kalman_gain"] = design["kalman_gain"];
          e["estimator_spectral_radius"] = design["estimator_spectral_radius"];
        }
        if (a.kind == "S+") {  // its own gain per scenario (add_ncs_designs)
          e["design"] = "LQR on eq. 8 at the mean delay tau_io of each scenario";
          e.erase("lqr_gain");
          e.erase("closed_loop_spectral_radius");
        }
      }
      r["approaches"].push_back(e);
    }
    // Links: point to point per scenario; bus messages by the CAN analysis.
    for (const engine::LinkSpec& l : f.links) {
      json e = {{"name", l.name}, {"from", l.from}, {"to", l.to}};
      if (l.bus.empty()) {
        e["base"] = link_summary(f.link_config(l.name));
        for (const engine::ScenarioSpec& s : f.scenarios) {
          if (s.delays.count(l.name) != 0 || s.losses.count(l.name) != 0) {
            e["scenarios"][s.name] = link_summary(f.link_config(l.name, &s));
          }
        }
      } else {
        e["bus"] = l.bus;
        e["id"] = l.id;
      }
      r["links"].push_back(e);
    }
    if (!f.buses.empty()) r["buses"] = analyze_buses(f);  // study_bus_analysis.hpp
    if (!f.cpus.empty()) {  // study_cpu.hpp: node jobs on input arrival need the period h
      const json& p = r.at("plant");
      if (p.contains("period_us")) {
        r["cpus"] = cpus_json(f, plan_cpus(f, static_cast<std::int64_t>(std::llround(p.at("period_us").get<double>()))));
      } else {
        r["cpus_not_analysed"] = "the inline continuous plant has no period h (the node jobs' inter-arrival)";
      }
    }
    // The grid.
    for (const engine::ScenarioSpec& s : f.scenarios) {
      const engine::ReferenceSpec* ref = s.reference ? &*s.reference : (f.reference ? &*f.reference : nullptr);
      std::map<std::string, double> params = s.params;
      if (ref != nullptr) {  // the set-point is the reference's: the square-wave params' defaults do not apply
        for (const char* key : {"amplitude_volts", "period_s"})
          if (s.params_given.count(key) == 0) params.erase(key);
      }
      r["scenarios"].push_back({{"name", s.name}, {"duration_s", s.duration_s.value_or(f.duration_s)}, {"params", params}});
      if (ref != nullptr) r["scenarios"].back()["reference"] = ref->describe();
    }
    r["grid"] = {{"approaches", f.approaches.size()}, {"scenarios", f.scenarios.size()},
                 {"runs_per_seed", f.approaches.size() * f.scenarios.size()},
                 {"runs", f.approaches.size() * f.scenarios.size() * f.seeds}};
    return r;
  } catch (const InputError& e) {
    throw InputError(f.source + ": " + e.what());
  }
}

void add_ncs_designs(json& r, const NcsStudy& s) {
  std::size_t index = 0;
  for (auto& a : r["approaches"]) {
    const std::size_t i = index++;
    if (i < s.discretizations.size() && one_shot_kind(a.at("kind").get<std::string>())) {
      a["discretizer"] = discretizer_json(s.discretizations[i]);
    }
    if (a.at("kind") == "AKl") {  // D = max sc + max ca + max τ_c (the controller job's WCRT on a CPU)
      for (const ncs::Scenario& sc : s.scenarios) a["per_scenario"][sc.name] = {{"late_sampling_d_us", s.ctx->worst_chain_us(sc)}};
    }
    if (a.at("kind") != "S+") continue;
    for (const ncs::Scenario& sc : s.scenarios) {
      const double tau = s.ctx->mean_tau_io_us(sc);
      const auto g = ncs::delay_compensated_gain(*s.ctx, tau);
      a["per_scenario"][sc.name] = {{"tau_io_us", tau}, {"gain_x_u", {g[0], g[1], g[2]}}};
    }
  }
}

void attach_bus_bounds(NcsStudy& s, const json& r) {
  for (NcsStudy& l : s.loops) attach_bus_bounds(l, r);
  s.bus_response_us.assign(s.scenarios.size(), {});
  if (!r.contains("buses")) return;
  for (std::size_t k = 0; k < s.scenarios.size(); ++k) {
    for (const json& b : r.at("buses")) {
      const std::string& name = s.scenarios[k].name;
      const json& list = b.contains("scenarios") && b.at("scenarios").contains(name) ? b.at("scenarios").at(name) : b.at("messages");
      for (const json& m : list) {
        if (m.at("kind") != "link") continue;
        std::string leg = s.link_names.empty() ? m.at("name").get<std::string>() : "";  // "" when another loop's
        for (const auto& [g, nm] : s.link_names)
          if (nm == m.at("name").get<std::string>()) leg = g;
        if (leg.empty()) continue;
        const json& w = m.at("worst_response_us");
        s.bus_response_us[k][leg] = w.is_null() ? std::nullopt : std::optional<double>(w.get<double>());
      }
    }
  }
}

}  // namespace oneshot::study
