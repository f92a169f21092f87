/// @file study_petc_map.cpp
/// @brief A "study": "petc" file mapped onto the petc study's closed loop (see
///        study_petc_study.hpp): the schema, the mapping and its refusals, the design that
///        `study check` prints.
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "petc_design.hpp"
#include "petc_experiments.hpp"
#include "study_fields.hpp"
#include "study_petc_study.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {

namespace {

using engine::InputError;
namespace pt = sim::petc;

constexpr double kPetcAbsent = -1;  // an absent approach param reads this (below every range)

/// The node slots of the petc loop and their triggers (null: absent or periodic every 1).
struct PetcNodes {
  std::string sensor, controller, actuator;
  const engine::TriggerSpec* sensor_mtm = nullptr;
  const engine::TriggerSpec* controller_mtm = nullptr;
  std::size_t sensor_index = 0, controller_index = 0;
};

/// Checks a node's trigger: absent, periodic every 1, or MTM with the compiled k_max (the
/// horizon H) and k_ref_max 0; returns the MTM trigger or null.
const engine::TriggerSpec* petc_trigger(const engine::NodeSpec& n, const std::string& f) {
  if (!n.trigger) return nullptr;
  const engine::TriggerSpec& t = *n.trigger;
  if (t.rule == engine::TriggerSpec::Rule::kPeriodic) {
    if (t.every != 1) refuse(f + ".trigger.every", "must be 1 (periodic: every period, the TTS rule)");
    return nullptr;
  }
  if (t.rule != engine::TriggerSpec::Rule::kMtm)
    refuse(f + ".trigger.rule", "the petc nodes trigger under MTM (or periodic every 1)");
  if (t.k_max != pt::kHorizon)
    refuse(f + ".trigger.k_max", "must be " + std::to_string(pt::kHorizon) +
                                     ": the safety send after H periods, H the packets' horizon (compiled in)");
  if (t.k_ref_max != 0) refuse(f + ".trigger.k_ref_max", "must be 0 (the unit step at k = 0 sends the sample taken then)");
  return &t;
}

/// Checks the three nodes: a sensor (timer at T), a controller (on arrival), an actuator (timer at T).
PetcNodes check_petc_nodes(const engine::StudyFile& file, std::int64_t period_us) {
  PetcNodes out;
  for (std::size_t i = 0; i < file.nodes.size(); ++i) {
    const engine::NodeSpec& n = file.nodes[i];
    const std::string f = at("nodes", i);
    std::string* slot = n.role == "sensor" ? &out.sensor : n.role == "controller" ? &out.controller : &out.actuator;
    if (!slot->empty()) refuse(f + ".role", "a second " + n.role + " (the petc loop has one sensor, one controller, one actuator)");
    *slot = n.name;
    const std::string mode = n.role == "controller" ? "arrival" : "timer";
    if (n.mode != mode)
      refuse(f + ".mode", "'" + n.mode + "': the petc " + n.role +
                              (n.role == "controller" ? " computes on each sample's arrival (mode arrival)"
                                                      : " runs on its timer at the plant's period (mode timer)"));
    if (n.mode == "timer" && n.period.count() != period_us * 1000)
      refuse(f + ".period_us", "must be the plant's period " + std::to_string(period_us) + " us");
    if (n.clock_offset.count() != 0) refuse(f + ".clock_offset_us", "must be 0 (the petc nodes share the plant's clock)");
    if (!n.cpu.empty()) refuse(f + ".cpu", "no CPU in the petc loop");
    if (n.role == "actuator") {
      if (n.trigger) refuse(f + ".trigger", "the actuator applies its packet every period: no trigger");
    } else if (n.role == "sensor") {
      out.sensor_mtm = petc_trigger(n, f);
      out.sensor_index = i;
    } else {
      out.controller_mtm = petc_trigger(n, f);
      out.controller_index = i;
    }
  }
  if (out.sensor.empty() || out.controller.empty() || out.actuator.empty())
    refuse("nodes", "the petc loop needs a sensor, a controller and an actuator");
  return out;
}

/// Checks a link's (or its scenario override's) delay and loss: zero delay, no loss.
void check_petc_channel(const engine::LinkConfig& c, const std::string& delay_field, const std::string& loss_field) {
  if (c.delay.kind != engine::DelayModel::Kind::kConstant || c.delay.constant.count() != 0)
    refuse(delay_field, "'" + c.delay.describe() + "': the petc loop's links have zero delay (constant, delay_us 0)");
  if (c.loss.kind != engine::LossModel::Kind::kNone)
    refuse(loss_field, "'" + c.loss.describe() + "': the petc loop's links lose nothing (model none)");
}

/// The approach's parameter `key`, kPetcAbsent when the file does not give it.
double petc_param(const engine::ApproachSpec& a, const char* key) {
  const auto it = a.params.find(key);
  return it == a.params.end() ? kPetcAbsent : it->second;
}

/// One threshold of approach i: its param, or the node trigger's value; refused when neither.
double petc_threshold(const engine::ApproachSpec& a, std::size_t i, const char* key, const engine::TriggerSpec* t,
                      bool sigma, const char* node, bool& used) {
  const double v = petc_param(a, key);
  if (v != kPetcAbsent) return v;
  if (t == nullptr)
    refuse(at("approaches", i) + ".params." + key, std::string("missing: the ") + node +
                                                    "'s trigger is not mtm, so kind '" + a.kind + "' needs its own threshold");
  used = true;
  return sigma ? t->sigma : t->mtm_delta;
}

/// The scenario's parameter `key` when given, else `fallback`.
double scenario_param(const engine::ScenarioSpec& x, const char* key, double fallback) {
  return x.params_given.count(key) != 0 ? x.params.at(key) : fallback;
}

std::shared_ptr<const PetcStudy> map_petc(const engine::StudyFile& file) {
  if (file.study != "petc") refuse("study", "'" + file.study + "' is not 'petc'");
  if (!file.loops.empty()) refuse("loops", "the petc study runs one loop per file");
  if (file.plant.kind == engine::PlantSpec::Kind::kDiscrete)
    refuse("plant.discrete", "the petc loop reads a plant file of sections form with its disturbance model (give plant.file, e.g. hdd_numre.json)");
  if (file.plant.kind == engine::PlantSpec::Kind::kContinuous)
    refuse("plant.continuous", "the petc loop reads a plant file of sections form with its disturbance model (give plant.file, e.g. hdd_numre.json)");
  if (!file.buses.empty()) refuse("buses", "the petc loop's links are point to point");
  if (!file.cpus.empty()) refuse("cpus", "no CPU in the petc loop");
  auto out = std::make_shared<PetcStudy>();
  out->source = file.source;
  out->plant_path = plant_file_path(file);
  std::int64_t period_us = 0;
  try {
    const pt::PlantFacts p = pt::load_plant_facts(out->plant_path);
    if (p.augmented.a.rows != 12 || p.phi_p.rows != 10)
      throw std::invalid_argument("the petc loop is compiled for a 10-state plant with 2 disturbance states (this one: " +
                                  std::to_string(p.phi_p.rows) + " + " + std::to_string(p.augmented.a.rows - p.phi_p.rows) + ")");
    period_us = p.file.period_us;
  } catch (const std::exception& e) {
    refuse("plant.file", e.what());
  }
  const PetcNodes nodes = check_petc_nodes(file, period_us);
  if (file.links.size() != 2) refuse("links", "the petc loop has exactly two links, sensor -> controller and controller -> actuator");
  for (std::size_t i = 0; i < file.links.size(); ++i) {
    const engine::LinkSpec& l = file.links[i];
    const std::string f = at("links", i);
    if (!l.bus.empty()) refuse(f + ".bus", "the petc loop's links are point to point");
    const bool sc = l.from == nodes.sensor;
    if (sc && l.to != nodes.controller) refuse(f + ".to", "the sensor's link runs to the controller ('" + nodes.controller + "')");
    if (!sc && l.from != nodes.controller) refuse(f + ".from", "a link runs from the sensor or from the controller");
    if (!sc && l.to != nodes.actuator) refuse(f + ".to", "the controller's link runs to the actuator ('" + nodes.actuator + "')");
    std::string& name = sc ? out->sc : out->ca;
    if (!name.empty()) refuse(f + ".from", "a second link from the " + std::string(sc ? "sensor" : "controller"));
    name = l.name;
    check_petc_channel(file.link_config(l.name), f + ".delay", f + ".loss");
  }
  out->first_seed = file.first_seed;
  out->seeds = file.seeds;
  bool sensor_used = false, controller_used = false;
  for (std::size_t i = 0; i < file.approaches.size(); ++i) {
    out->approaches.push_back(file.approaches[i].name);
    out->kinds.push_back(file.approaches[i].kind);
  }
  for (std::size_t s = 0; s < file.scenarios.size(); ++s) {
    const engine::ScenarioSpec& x = file.scenarios[s];
    const std::string fs = at("scenarios", s);
    out->scenarios.push_back(x.name);
    for (std::size_t i = 0; i < file.links.size(); ++i) {
      const std::string& ln = file.links[i].name;
      check_petc_channel(file.link_config(ln, &x),
                         x.delays.count(ln) != 0 ? fs + ".links." + ln + ".delay" : at("links", i) + ".delay",
                         x.losses.count(ln) != 0 ? fs + ".links." + ln + ".loss" : at("links", i) + ".loss");
    }
    pt::PetcOptions opt;
    opt.plant_path = out->plant_path;
    const double steps = (x.duration_s ? *x.duration_s : file.duration_s) * 1e6 / static_cast<double>(period_us);
    if (!(std::round(steps) >= 1 && std::round(steps) <= 1e6) || std::fabs(steps - std::round(steps)) > 1e-9 * steps)
      refuse(x.duration_s ? fs + ".duration_s" : std::string("duration_s"),
             "must be a whole number (1 ... 1000000) of plant periods of " + std::to_string(period_us) + " us");
    opt.steps = static_cast<std::size_t>(std::llround(steps));
    const engine::ReferenceSpec* ref = x.reference ? &*x.reference : (file.reference ? &*file.reference : nullptr);
    if (ref != nullptr) {
      if (ref->kind != engine::ReferenceSpec::Kind::kSteps)
        refuse(ref->field + ".kind", "the petc loop runs a step r at k = 0 only (kind steps, one step at t_s 0)");
      if (ref->steps.size() != 1 || ref->steps[0].first != 0)
        refuse(ref->field + ".steps", "one step at t_s 0 only (the petc loop's reference is constant from k = 0)");
      if (ref->steps[0].second == 0)
        refuse(ref->field + ".steps", "a zero step: N_E divides by the TTS response's ISE, 0 then");
      opt.reference = ref->steps[0].second;
    }
    opt.ratio = static_cast<std::size_t>(scenario_param(x, "ratio", 2));
    opt.dob_cutoff_hz = scenario_param(x, "dob_cutoff_hz", 1000);
    opt.sigma_w = scenario_param(x, "sigma_w", -1);
    opt.sigma_v = scenario_param(x, "sigma_v", -1);
    opt.sample_at_update = scenario_param(x, "sample_at_update", 0) != 0;
    opt.frozen_noise = scenario_param(x, "frozen_noise", 0) != 0;
    const bool noise = scenario_param(x, "noise", 1) != 0;
    const pt::MrciDesign mrci = pt::brief_mrci(opt.ratio);
    if (mrci.fast_count != 1 || mrci.slow_count != 2)
      refuse(fs + ".params.ratio", "m = " + std::to_string(opt.ratio) +
                                       " splits the controller into other than 2 slow + 1 fast modes, which the node is compiled for");
    try {
      out->setups.push_back(pt::make_setup(opt));
    } catch (const std::exception& e) {
      refuse(x.params_given.count("dob_cutoff_hz") != 0 ? fs + ".params.dob_cutoff_hz" : fs, e.what());
    }
    for (std::size_t i = 0; i < file.approaches.size(); ++i) {
      const engine::ApproachSpec& a = file.approaches[i];
      pt::CaseSpec c;
      c.name = a.name;
      c.label = a.kind;
      if (a.kind == "tts") {
        c.controller = pt::ControllerKind::kTts;
        for (const char* k : {"sigma_s", "delta_s", "sigma_c", "delta_c"})
          if (petc_param(a, k) != kPetcAbsent)
            refuse(at("approaches", i) + ".params." + k, "not a parameter of kind 'tts' (it sends every period)");
      } else {
        if (a.kind == "hold") {
          c.controller = pt::ControllerKind::kHold;
        } else if (a.kind == "numre-augmented" || a.kind == "numre-dob" || a.kind == "numre-eso") {
          c.controller = pt::ControllerKind::kNumre;
          c.observer = a.kind == "numre-augmented" ? pt::ObserverKind::kAugmented
                       : a.kind == "numre-dob"     ? pt::ObserverKind::kDob
                                                   : pt::ObserverKind::kEso;
        } else {
          refuse(at("approaches", i) + ".kind", "'" + a.kind + "' (tts, hold, numre-augmented, numre-dob, numre-eso)");
        }
        c.sigma_s = petc_threshold(a, i, "sigma_s", nodes.sensor_mtm, true, "sensor", sensor_used);
        c.delta_s = petc_threshold(a, i, "delta_s", nodes.sensor_mtm, false, "sensor", sensor_used);
        c.sigma_c = petc_threshold(a, i, "sigma_c", nodes.controller_mtm, true, "controller", controller_used);
        c.delta_c = petc_threshold(a, i, "delta_c", nodes.controller_mtm, false, "controller", controller_used);
      }
      const double an = petc_param(a, "noise");
      c.noise = noise && an != 0;
      if (out->runs.size() <= i) out->runs.resize(i + 1);
      out->runs[i].push_back(c);
    }
  }
  if (nodes.sensor_mtm != nullptr && !sensor_used && !file.scenarios.empty())
    refuse(at("nodes", nodes.sensor_index) + ".trigger",
           "no approach uses its thresholds (every approach is tts or gives sigma_s and delta_s): make it periodic every 1 or drop it");
  if (nodes.controller_mtm != nullptr && !controller_used && !file.scenarios.empty())
    refuse(at("nodes", nodes.controller_index) + ".trigger",
           "no approach uses its thresholds (every approach is tts or gives sigma_c and delta_c): make it periodic every 1 or drop it");
  return out;
}

const char* controller_name(pt::ControllerKind k) {
  return k == pt::ControllerKind::kTts ? "tts" : k == pt::ControllerKind::kHold ? "hold" : "numre";
}

const char* observer_name(pt::ObserverKind k) {
  return k == pt::ObserverKind::kAugmented ? "augmented" : k == pt::ObserverKind::kDob ? "dob" : "eso";
}

}  // namespace

nlohmann::json petc_case_json(const pt::CaseSpec& c) {
  nlohmann::json j = {{"controller", controller_name(c.controller)}, {"noise", c.noise}};
  if (c.controller == pt::ControllerKind::kNumre) j["observer"] = observer_name(c.observer);
  if (c.controller != pt::ControllerKind::kTts)
    j.update({{"sigma_s", c.sigma_s}, {"delta_s", c.delta_s}, {"sigma_c", c.sigma_c}, {"delta_c", c.delta_c}});
  return j;
}

const engine::StudySchema& petc_schema() {
  static const engine::StudySchema schema = [] {
    engine::StudySchema s;
    s.study = "petc";
    s.approach_kinds = {"tts", "hold", "numre-augmented", "numre-dob", "numre-eso"};
    s.approach_params = {{"sigma_s", 0, 1e6, false, false, kPetcAbsent}, {"delta_s", 0, 1e12, false, false, kPetcAbsent},
                         {"sigma_c", 0, 1e6, false, false, kPetcAbsent}, {"delta_c", 0, 1e12, false, false, kPetcAbsent},
                         {"noise", 0, 1, true, false, kPetcAbsent}};
    s.scenario_params = {{"noise", 0, 1, true, false, 1},         {"sigma_w", 0, 1e3, false, false, -1},
                         {"sigma_v", 0, 1e3, false, false, -1},   {"ratio", 1, 16, true, false, 2},
                         {"dob_cutoff_hz", 1, 1e6, false, false, 1000}, {"sample_at_update", 0, 1, true, false, 0},
                         {"frozen_noise", 0, 1, true, false, 0}};
    return s;
  }();
  return schema;
}

std::shared_ptr<const PetcStudy> map_petc_study(const engine::StudyFile& file) {
  try {
    return map_petc(file);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(file.source + ":", 0) == 0) throw;
    throw InputError(file.source + ": " + what);
  }
}

void add_petc_design(nlohmann::json& r, const PetcStudy& s) {
  nlohmann::json d;
  d["plant_file"] = s.plant_path;
  d["links"] = {{"sc", s.sc}, {"ca", s.ca}};
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    const pt::PetcSetup& st = s.setups[x];
    nlohmann::json e = {{"name", s.scenarios[x]}, {"config", pt::setup_config(st)}};
    const nlohmann::json design = pt::design_json(st.plant, st.mrci, st.dob, st.var_d);
    e["design"] = design;
    d["scenarios"].push_back(e);
  }
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json e = {{"name", s.approaches[a]}, {"kind", s.kinds[a]}, {"per_scenario", nlohmann::json::array()}};
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) e["per_scenario"].push_back(petc_case_json(s.runs[a][x]));
    d["approaches"].push_back(e);
  }
  r["petc"] = d;
}

std::string describe_petc(const nlohmann::json& r) {
  const nlohmann::json& d = r.at("petc");
  std::ostringstream o;
  o << "petc loop: plant file " << d.at("plant_file").get<std::string>() << ", links " << d.at("links").at("sc").get<std::string>()
    << " (sensor -> controller), " << d.at("links").at("ca").get<std::string>() << " (controller -> actuator), zero delay, no loss\n";
  for (const nlohmann::json& x : d.value("scenarios", nlohmann::json::array())) {
    const nlohmann::json& c = x.at("config");
    const nlohmann::json& g = x.at("design");
    const nlohmann::json& m = g.at("mrci");
    o << "  scenario " << x.at("name").get<std::string>() << ": K = " << c.at("steps") << " periods of "
      << g.at("plant").at("period_us") << " us, r = " << c.at("reference") << ", sigma_w " << c.at("sigma_w") << ", sigma_v "
      << c.at("sigma_v") << ", H = " << c.at("horizon") << ", TTS ISE " << c.at("ise") << "\n";
    o << "    MRCI m = " << m.at("ratio") << ": " << m.at("slow_modes").size() << " slow modes + the fast part, CS = " << m.at("cs");
    for (const nlohmann::json& sm : m.at("slow_modes"))
      o << "; slow pole " << sm.at("pole") << " -> " << sm.at("slow_pole") << " (phase " << sm.at("phase") << ")";
    o << "; fast part " << m.at("fast_part").at("numerator").dump() << " / " << m.at("fast_part").at("denominator").dump()
      << " (powers of z, highest first)";
    o << "\n    DOB: Q cutoff " << g.at("dob").at("cutoff_hz") << " Hz, rho = " << g.at("dob").at("delay") << ", gamma (d->d-dhat) "
      << g.at("dob").at("gamma_d_to_error") << "; noise accumulation "
      << c.at("noise_accumulation").get<std::string>() << ", sample at update " << c.at("sample_at_update") << "\n";
  }
  for (const nlohmann::json& a : d.value("approaches", nlohmann::json::array())) {
    o << "  approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>() << "):";
    const nlohmann::json& c = a.at("per_scenario").at(0);
    if (c.contains("sigma_s"))
      o << " sensor MTM sigma_s " << c.at("sigma_s") << ", delta_s " << c.at("delta_s") << "; controller MTM sigma_c "
        << c.at("sigma_c") << ", delta_c " << c.at("delta_c") << ";";
    else
      o << " both nodes send every period;";
    o << " noise " << (c.at("noise").get<bool>() ? "on" : "off") << (a.at("per_scenario").size() > 1 ? " (first scenario)" : "")
      << "\n";
  }
  return o.str();
}

}  // namespace oneshot::study
