/// @file study_sod_map.cpp
/// @brief A "study": "sod" file mapped onto the send-on-delta study's run (sim_host/sod/sod_sim.hpp;
///        see study_sod_runner.hpp): the schema, the mapping and its refusals, `study check`'s
///        resolution of the file (the δt design and the sod section: study_sod_design.cpp).
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_fields.hpp"
#include "study_plant_map.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"

namespace oneshot::study {

namespace {

using engine::InputError;

constexpr double kSodAbsent = 0;  // an absent approach param reads this (below every range)

/// The approach's parameter `key`, kSodAbsent when the file does not give it.
double sod_param(const engine::ApproachSpec& a, const char* key) {
  const auto it = a.params.find(key);
  return it == a.params.end() ? kSodAbsent : it->second;
}

/// The approach's parameter `key` must be absent (`why`: what it would mean elsewhere).
void refuse_sod_param(const engine::ApproachSpec& a, std::size_t i, const char* key, const std::string& why) {
  if (sod_param(a, key) != kSodAbsent) refuse(at("approaches", i) + ".params." + key, why);
}

/// The three nodes: two sensors (in file order: y1, y2) with their send-on-delta thresholds,
/// one controller (the receiver and estimator); every node a timer at the plant's period.
void map_sod_nodes(const engine::StudyFile& file, std::int64_t period_us, SodStudy& out) {
  std::size_t sensors = 0;
  std::size_t given = 0;
  for (std::size_t i = 0; i < file.nodes.size(); ++i) {
    const engine::NodeSpec& n = file.nodes[i];
    const std::string f = at("nodes", i);
    if (n.role != "sensor" && n.role != "controller")
      refuse(f + ".role", "'" + n.role + "': the sod study has two sensor nodes and one controller (the estimator); no actuator "
                          "(the input is the scenario's step)");
    if (n.role == "sensor" && sensors == sod::kNodes) refuse(f + ".role", "a third sensor (the sod plant has two outputs, one node each)");
    if (n.role == "controller" && !out.estimator.empty()) refuse(f + ".role", "a second controller (one estimator)");
    if (n.mode != "timer") refuse(f + ".mode", "'" + n.mode + "': every node runs on its timer at the plant's period");
    if (n.period.count() != period_us * 1000) refuse(f + ".period_us", "must be the plant's period " + std::to_string(period_us) + " us");
    if (n.clock_offset.count() != 0) refuse(f + ".clock_offset_us", "must be 0 (the sensors sample and the estimator runs at kT)");
    if (!n.cpu.empty()) refuse(f + ".cpu", "no CPU in the sod study");
    if (n.role == "controller") {
      if (n.trigger) refuse(f + ".trigger", "the estimator sends nothing: a trigger is the sensors' rule");
      out.estimator = n.name;
      continue;
    }
    if (!n.trigger || n.trigger->rule != engine::TriggerSpec::Rule::kSendOnDelta)
      refuse(f + ".trigger", "a sensor's rule is send_on_delta with its delta [dy] (approach kind periodic sends every "
                             "params.every-th sample instead)");
    if (n.trigger->delta.size() != 1) refuse(f + ".trigger.delta", "one threshold dy: the node reads one output");
    out.sensors[sensors] = n.name;
    out.delta_y[sensors] = n.trigger->delta[0];
    out.n_t[sensors] = n.trigger->time_steps;
    given += n.trigger->time_steps > 0 ? 1U : 0U;
    if (given != 0 && given != sensors + 1)
      refuse(f + ".trigger.time_steps", "give time_steps on both sensors (msod's n_t) or on neither (n_t from the dt design)");
    ++sensors;
  }
  if (sensors != sod::kNodes || out.estimator.empty())
    refuse("nodes", "the sod study needs two sensors (y1, y2 in file order) and one controller (the estimator)");
  out.n_t_given = given == sod::kNodes;
}

/// Link i from sensor i to the estimator, no delay, Bernoulli loss (or none).
void map_sod_links(const engine::StudyFile& file, SodStudy& out) {
  if (file.links.size() != sod::kNodes) refuse("links", "the sod study has two links, one per sensor to the estimator");
  for (std::size_t i = 0; i < file.links.size(); ++i) {
    const engine::LinkSpec& l = file.links[i];
    const std::string f = at("links", i);
    if (!l.bus.empty()) refuse(f + ".bus", "the sod study's links are point to point");
    if (l.to != out.estimator) refuse(f + ".to", "the links run to the estimator ('" + out.estimator + "')");
    std::size_t node = sod::kNodes;
    for (std::size_t k = 0; k < sod::kNodes; ++k)
      if (l.from == out.sensors[k]) node = k;
    if (node == sod::kNodes || !out.links[node].empty()) refuse(f + ".from", "one link from each sensor");
    out.links[node] = l.name;
    if (l.delay.lower_bound().count() != 0 || !l.delay.upper_bound() || l.delay.upper_bound()->count() != 0)
      refuse(f + ".delay", "the sod study's links have no delay: constant 0 (a packet is used at the step that sent it)");
  }
}

/// ξ of link `name` in scenario `x` (index `s`): Bernoulli (or none: 0).
double sod_link_loss(const engine::StudyFile& file, const engine::ScenarioSpec& x, std::size_t s, std::size_t link) {
  const std::string& name = file.links[link].name;
  const engine::LinkConfig c = file.link_config(name, &x);
  const std::string f = x.losses.count(name) != 0 ? at("scenarios", s) + ".links." + name + ".loss" : at("links", link) + ".loss";
  if (x.delays.count(name) != 0) {
    const engine::DelayModel& d = x.delays.at(name);
    if (d.lower_bound().count() != 0 || !d.upper_bound() || d.upper_bound()->count() != 0)
      refuse(at("scenarios", s) + ".links." + name + ".delay", "the sod study's links have no delay: constant 0");
  }
  if (c.loss.kind == engine::LossModel::Kind::kNone) return 0;
  if (c.loss.kind != engine::LossModel::Kind::kBernoulli)
    refuse(f, "the sod study's links lose packets independently: bernoulli (or no loss), not " + c.loss.describe());
  return c.loss.p;
}

std::shared_ptr<const SodStudy> map_sod(const engine::StudyFile& file) {
  if (file.study != "sod") refuse("study", "'" + file.study + "' is not 'sod'");
  if (!file.loops.empty()) refuse("loops", "the sod study runs one plant per file");
  if (file.plant.kind == engine::PlantSpec::Kind::kContinuous)
    refuse("plant.continuous", "give plant.file (a plant file with n = 2, m = 1, p = 2, no disturbance input and diagonal R)");
  if (file.plant.kind == engine::PlantSpec::Kind::kDiscrete)
    refuse("plant.discrete", "give plant.file (a plant file with n = 2, m = 1, p = 2, no disturbance input and diagonal R)");
  if (!file.buses.empty()) refuse("buses", "the sod study's links are point to point");
  if (!file.cpus.empty()) refuse("cpus", "no CPU in the sod study");
  if (file.reference) refuse("reference", "the sod study's input is a step: scenarios[i].params.amplitude");
  auto out = std::make_shared<SodStudy>();
  out->source = file.source;
  out->plant_path = plant_file_path(file);
  try {
    out->model = sod::load_sod_model(out->plant_path);
  } catch (const std::exception& e) {
    refuse("plant.file", e.what());
  }
  const std::int64_t period_us = out->model.period_us;
  map_sod_nodes(file, period_us, *out);
  map_sod_links(file, *out);
  out->first_seed = file.first_seed;
  out->seeds = file.seeds;
  for (std::size_t i = 0; i < file.approaches.size(); ++i) {
    const engine::ApproachSpec& a = file.approaches[i];
    const std::string f = at("approaches", i);
    SodApproach p;
    p.name = a.name;
    p.kind = a.kind;
    if (a.kind == "sod-held" || a.kind == "sod-kf") {
      p.sender = sod::SenderKind::kSod;
      p.filter = a.kind == "sod-held" ? sod::FilterKind::kHeld : sod::FilterKind::kPredictOnly;
      refuse_sod_param(a, i, "mu", "not a parameter of kind '" + a.kind + "' (msod's design bound)");
      refuse_sod_param(a, i, "every", "not a parameter of kind '" + a.kind + "' (periodic's)");
    } else if (a.kind == "msod") {
      p.sender = sod::SenderKind::kModifiedSod;
      p.filter = sod::FilterKind::kHeld;
      refuse_sod_param(a, i, "every", "not a parameter of kind 'msod' (periodic's)");
      if (out->n_t_given) refuse_sod_param(a, i, "mu", "n_t is given by the sensors' trigger.time_steps: no dt design");
      if (sod_param(a, "mu") != kSodAbsent) p.mu = sod_param(a, "mu");
    } else if (a.kind == "periodic") {
      p.sender = sod::SenderKind::kPeriodic;
      p.filter = sod::FilterKind::kPredictOnly;
      refuse_sod_param(a, i, "mu", "not a parameter of kind 'periodic' (msod's design bound)");
      if (sod_param(a, "every") != kSodAbsent) p.every = static_cast<std::uint32_t>(sod_param(a, "every"));
    } else {
      refuse(f + ".kind", "'" + a.kind + "' (sod-held, sod-kf, msod, periodic)");
    }
    out->approaches.push_back(p);
  }
  bool msod = false;
  for (const SodApproach& p : out->approaches) msod = msod || p.sender == sod::SenderKind::kModifiedSod;
  if (out->n_t_given && !msod) {  // only msod's sender takes the time rule: it would be ignored
    for (std::size_t i = 0; i < file.nodes.size(); ++i)
      if (file.nodes[i].role == "sensor")
        refuse(at("nodes", i) + ".trigger.time_steps", "no approach is msod (the time rule n_t is msod's; sod-held, sod-kf and "
                                                       "periodic send without it)");
  }
  for (std::size_t s = 0; s < file.scenarios.size(); ++s) {
    const engine::ScenarioSpec& x = file.scenarios[s];
    const std::string fs = at("scenarios", s);
    if (x.reference) refuse(fs + ".reference", "the sod study's input is a step: params.amplitude");
    SodScenario c;
    c.name = x.name;
    const double steps = (x.duration_s ? *x.duration_s : file.duration_s) * 1e6 / static_cast<double>(period_us);
    if (!(std::round(steps) >= 1) || std::round(steps) > 2147483648.0 || std::fabs(steps - std::round(steps)) > 1e-9 * steps)
      refuse(x.duration_s ? fs + ".duration_s" : std::string("duration_s"),
             "must be a whole number (>= 1) of plant periods of " + std::to_string(period_us) + " us");
    c.steps = std::llround(steps);
    c.amplitude = x.params.count("amplitude") != 0 ? x.params.at("amplitude") : 1.0;
    c.loss = sod_link_loss(file, x, s, 0);
    for (std::size_t l = 1; l < file.links.size(); ++l)
      if (sod_link_loss(file, x, s, l) != c.loss) {
        const std::string& name = file.links[l].name;
        refuse(x.losses.count(name) != 0 ? fs + ".links." + name + ".loss" : at("links", l) + ".loss",
               "both links lose at one rate xi (the sod study's run draws both at one probability)");
      }
    out->scenarios.push_back(c);
  }
  return out;
}

}  // namespace

const engine::StudySchema& sod_schema() {
  static const engine::StudySchema schema = [] {
    engine::StudySchema s;
    s.study = "sod";
    s.approach_kinds = {"sod-held", "sod-kf", "msod", "periodic"};
    s.approach_params = {{"mu", 1.000001, 1e6, false, false, kSodAbsent}, {"every", 1, 1e6, true, false, kSodAbsent}};
    s.scenario_params = {{"amplitude", -1e6, 1e6, false, false, 1}};
    return s;
  }();
  return schema;
}

nlohmann::json resolve_sod_study(const engine::StudyFile& file) {
  if (file.plant.kind != engine::PlantSpec::Kind::kFile || !file.loops.empty()) return resolve_study(file);  // refused by the mapping
  design::PlantDescription p;
  try {
    p = design::load_plant_file(plant_file_path(file));
  } catch (const std::exception& e) {
    throw InputError(file.source + ": field 'plant.file': " + std::string(e.what()));
  }
  engine::StudyFile open_loop = file;  // the plant's shape only: nothing to design
  open_loop.plant.kind = engine::PlantSpec::Kind::kContinuous;
  open_loop.plant.continuous = engine::ContinuousModel{};
  open_loop.plant.continuous.a = p.a;
  open_loop.plant.continuous.b = p.b;
  open_loop.plant.continuous.c = p.c;
  open_loop.plant.design = nullptr;
  nlohmann::json r = resolve_study(open_loop);
  r["plant"] = {{"kind", "file"}, {"file", p.source}, {"name", p.name}, {"form", design::to_string(p.form)}, {"n", p.n()},
                {"m", p.m()}, {"p", p.p()}, {"period_us", p.period_us}, {"designed", false},
                {"why_not_designed", "the sod study runs open loop (a step input): no controller; its estimators are the sod section's"}};
  for (nlohmann::json& a : r["approaches"]) a["design"] = "no controller (open loop): the estimator of its kind (sod section)";
  return r;
}

std::shared_ptr<const SodStudy> map_sod_study(const engine::StudyFile& file) {
  try {
    return map_sod(file);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(file.source + ":", 0) == 0) throw;
    throw InputError(file.source + ": " + what);
  }
}

engine::SweepSpec sod_sweep_spec(const SodStudy& s, std::size_t seeds, const char* experiment) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = experiment;
  for (const SodApproach& a : s.approaches) spec.approaches.push_back(a.name);
  for (const SodScenario& x : s.scenarios) spec.scenarios.push_back(x.name);
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  return spec;
}

}  // namespace oneshot::study
