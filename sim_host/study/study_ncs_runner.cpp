/// @file study_ncs_runner.cpp
/// @brief A study file mapped onto study ncs's loop (see study_ncs_runner.hpp).
#include "study_ncs_runner.hpp"

#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ncs_live.hpp"
#include "study_cpu.hpp"
#include "study_fields.hpp"
#include "study_one_shot_discretizer.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {
namespace {

using engine::InputError;

/// Why approach I, the reference of every ratio, would cost exactly 0 on `sc` ("" when it does
/// not): it starts on the set-point without delay or noise, so it costs nothing until the
/// set-point first changes (a square wave at T_r/2), and nothing at all when it never does.
/// Ratios to it would divide by 0.
std::string zero_reference_cost(const ncs::Context& ctx, const ncs::Scenario& sc) {
  const std::uint64_t k = ncs::first_setpoint_change(ctx, sc);
  if (k == 0) {
    return sc.setpoint_changes ? "the set-point never changes, so the reference approach I costs 0: no ratio to it"
                               : "amplitude 0 keeps the reference approach I at cost 0: no ratio to it";
  }
  const double first_switch_s = static_cast<double>(k) * static_cast<double>(ctx.period_us()) * 1e-6;
  if (!(sc.duration_s > first_switch_s)) {
    return "the run ends (" + std::to_string(sc.duration_s) + " s) before the first set-point switch at " +
           std::string(sc.setpoint_changes ? "" : "T_r/2 = ") + std::to_string(first_switch_s) +
           " s, so the reference approach I costs 0: no ratio to it";
  }
  return "";
}

}  // namespace

const NcsLeg* find_ncs_leg(const std::string& name) {
  for (const NcsLeg& g : kNcsLegs)
    if (name == g.name) return &g;
  return nullptr;
}

const engine::StudySchema& ncs_schema() {
  static const engine::StudySchema schema = [] {
    engine::StudySchema s;
    s.study = "ncs";
    for (ncs::Approach a : ncs::kAllApproaches) s.approach_kinds.emplace_back(ncs::name(a));
    for (ncs::Approach a : ncs::kOneShotApproaches) s.approach_kinds.emplace_back(ncs::name(a));
    // The one-shot filter's discretizer (study_one_shot_discretizer.hpp): a word, default generic.
    s.approach_params = {{"discretizer", 0, 0, false, false, 0, {"generic", "table", "nearest"}}};
    // amplitude_volts and period_s: required without a `reference` (map_ncs_study checks).
    s.scenario_params = {{"amplitude_volts", 0, 100, false, false, 0},
                         {"period_s", 1e-3, 1e6, false, false, 1},
                         {"noise_scale", 0, 1e6, false, false, 1}};
    return s;
  }();
  return schema;
}

NcsStudy map_ncs_study(const engine::StudyFile& file) {
  try {
    if (!file.loops.empty()) return map_ncs_loops(file);
    NcsStudy out;
    out.source = file.source;
    if (file.study != "ncs") refuse("study", "'" + file.study + "' has no runner yet (study run runs 'ncs' and 'dropping')");
    NcsPlant plant = map_ncs_plant(file);
    out.ctx = std::move(plant.ctx);
    out.plant_path = std::move(plant.plant_path);
    const std::string plant_field = std::move(plant.covariance_field);  // where the plant's measurement covariance is
    const std::int64_t h_us = out.ctx->period_us();
    // Nodes: one per role, the loop's addresses, timers at h for sensor and actuator.
    if (file.nodes.size() != 3) refuse("nodes", "study ncs runs exactly three nodes (sensor, controller, actuator)");
    const std::map<std::string, std::uint8_t> address = {
        {"sensor", ncs::kLiveSensor}, {"controller", ncs::kLiveController}, {"actuator", ncs::kLiveActuator}};
    std::map<std::string, std::string> by_role;  // role → node name
    // One-shot loops (OS, OSp, OSK): the controller runs a timer at kh + φ, the sensor may send on delta.
    bool one_shot = false;
    for (const engine::ApproachSpec& a : file.approaches) {
      for (ncs::Approach k : ncs::kOneShotApproaches) one_shot = one_shot || a.kind == ncs::name(k);
    }
    std::string sod_field;  // the sensor's event trigger, send-on-delta or MTM ("" when it has none)
    std::vector<double> sod_delta;
    std::uint32_t sod_time_steps = 0;
    std::optional<engine::TriggerSpec> mtm_rule;  // the sensor's MTM trigger (sod_field names it)
    std::int64_t phase_us = 0;
    for (std::size_t i = 0; i < file.nodes.size(); ++i) {
      const engine::NodeSpec& n = file.nodes[i];
      const std::string f = at("nodes", i);
      if (!by_role.emplace(n.role, n.name).second) refuse(f + ".role", "a second " + n.role + " (study ncs runs one of each)");
      if (n.address != address.at(n.role)) {
        refuse(f + ".address", "the ncs loop's " + n.role + " has address " + std::to_string(address.at(n.role)));
      }
      const bool timed_controller = one_shot && n.role == "controller";
      if (n.clock_offset.count() != 0 && !timed_controller) {
        refuse(f + ".clock_offset_us", "study ncs runs its nodes on one clock (0 only; the one-shot controller's gives its phase)");
      }
      const bool sod = n.trigger && n.trigger->rule == engine::TriggerSpec::Rule::kSendOnDelta && n.role == "sensor";
      const bool mtm = n.trigger && n.trigger->rule == engine::TriggerSpec::Rule::kMtm && n.role == "sensor";
      if (mtm) {
        if (!one_shot) refuse(f + ".trigger", "MTM runs with the one-shot approaches only (OS, OSp, OSK)");
        sod_field = f + ".trigger";
        mtm_rule = *n.trigger;
      } else if (sod) {
        if (!one_shot) refuse(f + ".trigger", "send-on-delta runs with the one-shot approaches only (OS, OSp, OSK)");
        if (n.trigger->delta.size() != ncs::kP) {
          refuse(f + ".trigger.delta", "one threshold per output: " + std::to_string(ncs::kP) + " values, not " +
                                           std::to_string(n.trigger->delta.size()));
        }
        sod_field = f + ".trigger";
        sod_delta = n.trigger->delta;
        sod_time_steps = n.trigger->time_steps;
      } else if (n.trigger && !(n.trigger->rule == engine::TriggerSpec::Rule::kPeriodic && n.trigger->every == 1)) {
        refuse(f + ".trigger", "study ncs samples every period (periodic, every 1, or a sensor's send-on-delta or MTM with OS, OSp)");
      }
      if (timed_controller) {
        if (n.mode != "timer") refuse(f + ".mode", "the one-shot controller (OS, OSp, OSK) runs a timer at h");
        if (n.period.count() != h_us * 1000) refuse(f + ".period_us", "must be the plant's period h = " + std::to_string(h_us) + " us");
        const std::int64_t phi = n.clock_offset.count() / 1000;
        if (!(phi > 0 && phi < h_us) || phi * 1000 != n.clock_offset.count()) {
          refuse(f + ".clock_offset_us", "the one-shot controller's phase: its timer fires at kh + clock_offset_us, 0 < it < h = " +
                                             std::to_string(h_us) + " us (whole us)");
        }
        phase_us = phi;
      } else if (n.role == "controller") {
        if (n.mode != "arrival") refuse(f + ".mode", "the ncs controller computes on arrival");
      } else {
        if (n.mode != "timer") {
          refuse(f + ".mode", "the ncs " + n.role + " runs a timer at h (its sampling- or actuation-synchronized approaches)");
        }
        if (n.period.count() != h_us * 1000) {
          refuse(f + ".period_us", "must be the plant's period h = " + std::to_string(h_us) + " us");
        }
      }
    }
    // Links: the loop's legs, point to point or on a CAN bus.
    std::string first_bus_link;  // field of the first leg on a bus ("" when none)
    for (std::size_t i = 0; i < file.links.size(); ++i) {
      const engine::LinkSpec& l = file.links[i];
      const std::string f = at("links", i);
      // The leg a link is: its name must be the loop's, its ends the nodes of those roles.
      const NcsLeg* leg = find_ncs_leg(l.name);
      if (leg == nullptr) refuse(f + ".name", "study ncs has legs as, sc, ca only (the names of their random streams)");
      if (l.from != by_role.at(leg->from)) refuse(f + ".from", std::string("leg ") + leg->name + " leaves the " + leg->from);
      if (l.to != by_role.at(leg->to)) refuse(f + ".to", std::string("leg ") + leg->name + " reaches the " + leg->to);
      if (!l.bus.empty()) {
        if (l.name == "as") {
          refuse(f + ".bus", "the leg as serves the actuation-synchronized approaches only, which do not run on a CAN bus");
        }
        if (first_bus_link.empty()) first_bus_link = f + ".bus";
      }
      out.links.push_back(l.name);
    }
    {
      const design::PlantDescription& pd = out.ctx->plant();
      if (!file.buses.empty() && !out.ctx->board()) {
        refuse("buses", "the bus analysis takes the board's frames (its plant: 2 outputs, 1 input, C = I): a plant of n = " +
                        std::to_string(pd.a.rows) + ", m = " + std::to_string(pd.b.cols) + ", p = " + std::to_string(pd.c.rows) +
                        (out.ctx->identity_output() ? "" : " (C not I)") + " runs on point-to-point legs only");
      }
    }
    for (std::size_t b = 0; b < file.buses.size(); ++b) {
      bool used = false;
      for (const engine::LinkSpec& l : file.links) used = used || l.bus == file.buses[b].config.name;
      if (!used) refuse(at("buses", b), "no leg of the loop runs on it (its traffic would run on nothing)");
    }
    const auto has = [&](const char* nm) {
      for (const std::string& l : out.links)
        if (l == nm) return true;
      return false;
    };
    if (!has("sc") || !has("ca")) refuse("links", "study ncs needs the legs sc (sensor to controller) and ca (controller to actuator)");
    // Approaches: ncs names, I first.
    std::array<std::shared_ptr<const ncs::OneShotTriple>, ncs::kOneShotApproaches.size()> one_shot_triples{};
    for (std::size_t i = 0; i < file.approaches.size(); ++i) {
      const engine::ApproachSpec& a = file.approaches[i];
      const std::string f = at("approaches", i);
      bool known = false;
      for (ncs::Approach k : ncs::kAllApproaches) known = known || a.kind == ncs::name(k);
      for (ncs::Approach k : ncs::kOneShotApproaches) known = known || a.kind == ncs::name(k);
      if (!known) refuse(f + ".kind", "unknown kind '" + a.kind + "' (I, S, A, AK, AKx, AKl, SK, S+, IK, OS, OSp, OSK)");
      const ncs::Context& cx = *out.ctx;
      const std::string shape = "a plant of n = " + std::to_string(cx.states()) + ", m = " + std::to_string(cx.inputs()) +
                                ", p = " + std::to_string(cx.outputs());
      if (!cx.board() && !ncs::any_shape_approach(ncs::parse_any_approach(a.kind))) {
        refuse(f + ".kind", a.kind + " runs the board's plant (n = 2, m = 1, p = 2, C = I) only (its estimators, S+'s gain and the "
                            "one-shot loops are 2-state); " + shape + " runs I, S, SK, IK");
      }
      if (a.kind == "I" && cx.states() > ncs::kMaxStateFeedbackStates) {
        refuse(f + ".kind", "I sends the state x in one sensor frame (64 bytes: n <= 6 doubles); " + shape +
                            " runs IK as the reference (the first approach), SK");
      }
      if (a.kind == "S" && !cx.identity_output()) {
        refuse(f + ".kind", "S feeds y back as the state: it needs C = I (" + shape + "; SK and IK filter y)");
      }
      if (!a.params.empty()) refuse(f + ".params", "the ncs approaches take no parameters");
      if (a.name != a.kind) refuse(f + ".name", "must be its kind '" + a.kind + "' (the ncs table names approaches by kind)");
      const ncs::Approach ap = ncs::parse_any_approach(a.kind);
      if (one_shot && !ncs::one_shot(ap) && !ncs::delay_free(ap)) {
        refuse(f + ".kind", a.kind + " runs its controller on arrival: a file with one-shot approaches (OS, OSp, OSK) has a timer "
                            "controller; its other approaches can be I and IK only");
      }
      if (!sod_field.empty() && !ncs::one_shot(ap) && !ncs::delay_free(ap)) {
        refuse(f + ".kind", a.kind + " cannot use the sensor's event trigger (" + sod_field + ")");
      }
      if (sod_field.empty() && (ap == ncs::Approach::kOS || ap == ncs::Approach::kOSp)) {
        refuse(f + ".kind", a.kind + " needs an event-triggered sensor (nodes[].trigger {\"rule\": \"send_on_delta\", ...} or "
                            "{\"rule\": \"mtm\", ...}); OSK is the one-shot loop with a sensor that sends every sample");
      }
      if (mtm_rule && ap == ncs::Approach::kOS && mtm_rule->sigma != 0) {
        refuse(sod_field + ".sigma", "OS corrects with a silent sensor's held value within +-sqrt(delta): MTM with sigma = 0 "
                                     "only (sigma > 0 bounds it by y itself; OSp and OSK run with any sigma)");
      }
      if (!first_bus_link.empty() && ncs::one_shot(ap)) {
        refuse(f + ".kind", a.kind + ": the one-shot loops do not run on a CAN bus (" + first_bus_link + ")");
      }
      if (i == 0 && ap != ncs::Approach::kI && !(ap == ncs::Approach::kIK && out.ctx->states() > ncs::kMaxStateFeedbackStates)) {
        refuse(f + ".kind", "the first approach must be I (the reference of every ratio; IK for a plant of n > 6, which I cannot run)");
      }
      if (ncs::actuation_synchronized(ap) && !has("as")) {
        refuse(f + ".kind", a.kind + " is actuation-synchronized: it needs the leg as (actuator to sensor)");
      }
      for (ncs::Approach b : out.approaches)
        if (b == ap) refuse(f + ".kind", "'" + a.kind + "' twice");
      if (!first_bus_link.empty() && ncs::actuation_synchronized(ap)) {
        refuse(f + ".kind", a.kind + " is actuation-synchronized: its sensor reports on the request's arrival in a longer frame, "
                            "which the bus analysis (" + first_bus_link + ": the sensor on its timer) does not cover");
      }
      if (!first_bus_link.empty() && ap == ncs::Approach::kSPlus) {
        refuse(f + ".kind", "S+ designs on the legs' mean delays, which a leg on a CAN bus (" + first_bus_link +
                                ") does not have before the run");
      }
      // The one-shot filter's discretizer, designed from the plant (a table built now).
      const auto word = a.words.find("discretizer");
      OneShotDiscretizer disc = OneShotDiscretizer::kGeneric;
      if (word != a.words.end()) {
        if (!ncs::one_shot(ap)) {
          refuse(f + ".params.discretizer", a.kind + " runs no one-shot filter: the discretizer is the one-shot loops' (OS, OSp, OSK)");
        }
        disc = *one_shot_discretizer_named(word->second);
      }
      if (ncs::one_shot(ap)) {
        out.discretizations.push_back(design_one_shot_discretization(
            *out.ctx, disc, f + ".params.discretizer",
            file.plant.kind == engine::PlantSpec::Kind::kFile       ? "plant.file"
            : file.plant.kind == engine::PlantSpec::Kind::kDiscrete ? "plant.discrete"
                                                                    : "plant.continuous.table.max_bytes"));
        std::size_t slot = 0;
        while (ncs::kOneShotApproaches[slot] != ap) ++slot;
        one_shot_triples[slot] = out.discretizations.back().triple;
      } else {
        out.discretizations.emplace_back();
      }
      out.approaches.push_back(ap);
    }
    // Scenarios: ncs Scenario fields, legs from the file with the scenario's overrides.
    for (std::size_t i = 0; i < file.scenarios.size(); ++i) {
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
      sc.sod_delta = sod_delta;
      sc.sod_time_steps = sod_time_steps;
      if (mtm_rule) {
        sc.sensor_mtm = true;
        sc.mtm_sigma = mtm_rule->sigma;
        sc.mtm_delta = mtm_rule->mtm_delta;
        sc.mtm_k_max = mtm_rule->k_max;
        sc.mtm_k_ref_max = mtm_rule->k_ref_max;
      }
      sc.controller_phase_us = phase_us;
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
          static_cast<void>(ncs::half_wave_periods(*out.ctx, sc));
        } catch (const std::exception&) {
          refuse(period_field, "T_r/2 must be a whole number of periods h = " + std::to_string(h_us) + " us");
        }
      }
      if (!(sc.duration_s * 1e6 >= static_cast<double>(h_us))) refuse(f + ".duration_s", "shorter than one period h");
      if (ncs::first_setpoint_change(*out.ctx, sc) == 0) refuse(amplitude_field, zero_reference_cost(*out.ctx, sc));
      const std::string zero = zero_reference_cost(*out.ctx, sc);
      if (!zero.empty()) refuse(s.duration_s ? f + ".duration_s" : std::string("duration_s"), zero);
      for (ncs::Approach a : out.approaches) {
        const std::string g = f + " with approach " + ncs::name(a);
        if (a == ncs::Approach::kSPlus) {
          const double tau = out.ctx->mean_tau_io_us(sc);
          if (!(tau < static_cast<double>(h_us))) {
            refuse(g, "S+ designs on the mean delay tau_io = " + std::to_string(tau) + " us, which must be below h");
          }
          try {
            static_cast<void>(ncs::delay_compensated_split(*out.ctx, tau));
          } catch (const std::exception& e) {
            refuse(g, e.what());
          }
        }
        if (a == ncs::Approach::kAKl) {
          try {
            static_cast<void>(out.ctx->worst_chain_us(sc));
          } catch (const std::exception& e) {
            refuse(g, e.what());
          }
        }
      }
      sc.one_shot_triples = one_shot_triples;
      out.scenarios.push_back(sc);
    }
    if (one_shot) {
      // The one-shot filter corrects the outputs one at a time (a scalar correction each):
      // exact only for a diagonal measurement covariance.
      const auto r = out.ctx->controller_design(1).r;
      for (std::size_t i = 0; i < ncs::kP; ++i)
        for (std::size_t k = 0; k < ncs::kP; ++k)
          if (i != k && r(i, k) != 0) {
            refuse(plant_field, "the one-shot filter corrects the outputs one at a time: the measurement covariance R must "
                                 "be diagonal (R(" + std::to_string(i) + "," + std::to_string(k) + ") is not 0)");
          }
    }
    attach_controller_cpu(file, out);  // study_cpu.hpp: τ_c from the controller's CPU, when it has one
    for (const std::string& l : out.links) out.link_names[l] = l;
    out.first_seed = file.first_seed;
    out.seeds = file.seeds;
    return out;
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(file.source + ":", 0) == 0) throw;
    throw InputError(file.source + ": " + what);
  }
}

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
    const std::string zero = zero_reference_cost(*s.ctx, x);
    if (!zero.empty()) throw InputError("field '" + field + "': scenario " + x.name + ": " + zero);
  }
  s.scenarios = std::move(capped);
}

}  // namespace oneshot::study
