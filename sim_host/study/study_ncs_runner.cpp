/// @file study_ncs_runner.cpp
/// @brief A study file mapped onto study ncs's loop (see study_ncs_runner.hpp).
#include "study_ncs_runner.hpp"

#include <array>
#include <iterator>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ncs_live.hpp"
#include "study_cpu.hpp"
#include "study_fields.hpp"
#include "study_ncs_scenario_map.hpp"
#include "study_one_shot_discretizer.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {

using engine::InputError;

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
    std::map<std::string, std::int64_t> clocks_us;  // role → its clock offset φ (µs), when not 0
    for (std::size_t i = 0; i < file.nodes.size(); ++i) {
      const engine::NodeSpec& n = file.nodes[i];
      const std::string f = at("nodes", i);
      if (!by_role.emplace(n.role, n.name).second) refuse(f + ".role", "a second " + n.role + " (study ncs runs one of each)");
      if (n.address != address.at(n.role)) {
        refuse(f + ".address", "the ncs loop's " + n.role + " has address " + std::to_string(address.at(n.role)));
      }
      const bool timed_controller = one_shot && n.role == "controller";
      if (n.clock_offset.count() != 0 && !timed_controller) {
        // The node's clock reads t − φ: its timer at kh + φ, its stamps φ behind (ncs::Scenario::sensor_clock_us).
        if (one_shot) {
          refuse(f + ".clock_offset_us", "a file with one-shot approaches runs its sensor and actuator on one clock (0 only; the "
                                         "one-shot controller's gives its phase)");
        }
        if (!file.cpus.empty()) refuse(f + ".clock_offset_us", "clock offsets run without cpus (0 only in a file with cpus)");
        const std::int64_t phi = n.clock_offset.count() / 1000;
        if (!(phi >= 0 && phi < h_us) || phi * 1000 != n.clock_offset.count()) {
          refuse(f + ".clock_offset_us", "the " + n.role + "'s clock reads t - clock_offset_us (its timer at kh + it): 0 <= it < h = " +
                                             std::to_string(h_us) + " us (whole us)");
        }
        clocks_us[n.role] = phi;
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
    // Scenarios: ncs Scenario fields, legs from the file with the scenario's overrides (study_ncs_scenario_map.hpp).
    const NcsScenarioInputs inputs{sod_delta, sod_time_steps, mtm_rule, phase_us, one_shot_triples};
    for (std::size_t i = 0; i < file.scenarios.size(); ++i) {
      out.scenarios.push_back(map_ncs_scenario(file, i, out, inputs));
      ncs::Scenario& sc = out.scenarios.back();  // every scenario runs the nodes' clocks (only when not 0: the rest as it was)
      for (const auto& [role, phi] : clocks_us) {
        (role == "sensor" ? sc.sensor_clock_us : role == "controller" ? sc.controller_clock_us : sc.actuator_clock_us) = phi;
      }
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

}  // namespace oneshot::study
