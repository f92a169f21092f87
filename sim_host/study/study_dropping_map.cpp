/// @file study_dropping_map.cpp
/// @brief A "study": "dropping" file mapped onto the dropping study's closed loop (see
///        study_dropping_runner.hpp): the schema, the mapping and its refusals, the design that
///        `study check` prints.
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mare.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_dropping_runner.hpp"
#include "study_dropping_study.hpp"
#include "study_fields.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {

namespace {

using engine::InputError;

constexpr double kDropAbsent = 0;  // an absent approach/scenario param reads this (below every range)

/// Checks the two nodes: a sensor and a controller, both timers at the plant's period.
void check_drop_nodes(const engine::StudyFile& file, std::int64_t period_us, std::string& sensor, std::string& controller) {
  for (std::size_t i = 0; i < file.nodes.size(); ++i) {
    const engine::NodeSpec& n = file.nodes[i];
    const std::string f = at("nodes", i);
    std::string& slot = n.role == "sensor" ? sensor : controller;
    if (n.role != "sensor" && n.role != "controller")
      refuse(f + ".role", "'" + n.role + "': the dropping loop has a sensor and a controller only (the controller applies u_k itself)");
    if (!slot.empty()) refuse(f + ".role", "a second " + n.role + " (the dropping loop has one sensor and one controller)");
    slot = n.name;
    if (n.mode != "timer") refuse(f + ".mode", "'" + n.mode + "': both nodes run on their timer at the plant's period");
    if (n.period.count() != period_us * 1000)
      refuse(f + ".period_us", "must be the plant's period " + std::to_string(period_us) + " us");
    if (n.clock_offset.count() != 0) refuse(f + ".clock_offset_us", "must be 0 (the sensor samples and the controller computes at kT)");
    if (!n.cpu.empty()) refuse(f + ".cpu", "no CPU in the dropping loop");
    if (n.trigger && (n.role != "sensor" || n.trigger->rule != engine::TriggerSpec::Rule::kPeriodic || n.trigger->every != 1))
      refuse(f + ".trigger", "the sensor sends every sample (absent or periodic every 1)");
  }
  if (sensor.empty() || controller.empty()) refuse("nodes", "the dropping loop needs a sensor and a controller");
}

/// The square wave r_k of a scenario from `ref` (the file's or the scenario's; null: ±1, 4 s).
void apply_drop_reference(const engine::ReferenceSpec* ref, std::int64_t period_us, dropping::RunConfig& c) {
  if (ref == nullptr) return;
  if (ref->kind != engine::ReferenceSpec::Kind::kSquare)
    refuse(ref->field + ".kind", "the dropping loop runs a square wave r_k only");
  const double half_steps = ref->period_s * 0.5e6 / static_cast<double>(period_us);
  if (std::llround(half_steps) < 1 || std::fabs(half_steps - std::round(half_steps)) > 1e-9 * half_steps)
    refuse(ref->field + ".period_s", "half of it must be a whole number (>= 1) of plant periods");
  c.square_wave_period_s = ref->period_s;
  c.square_wave_amplitude = ref->amplitude_volts;
}

/// The approach's parameter `key`, kDropAbsent when the file does not give it.
double drop_param(const engine::ApproachSpec& a, const char* key) {
  const auto it = a.params.find(key);
  return it == a.params.end() ? kDropAbsent : it->second;
}

/// The approach's parameter `key` ("approaches[i].params.<key>") must be absent for its kind.
void refuse_drop_param(const engine::ApproachSpec& a, std::size_t i, const char* key) {
  if (drop_param(a, key) != kDropAbsent) refuse(at("approaches", i) + ".params." + key, "not a parameter of kind '" + a.kind + "'");
}

std::shared_ptr<const DroppingStudy> map_drop(const engine::StudyFile& file) {
  if (file.study != "dropping") refuse("study", "'" + file.study + "' is not 'dropping'");
  if (!file.loops.empty()) refuse("loops", "the dropping study runs one loop per file");
  if (file.plant.kind == engine::PlantSpec::Kind::kDiscrete)
    refuse("plant.discrete", "an inline discrete plant carries no measurement covariance R nor initial covariance P0, which the "
                             "filters need: give plant.file (a discrete plant file with n = 3, m = 1, p = 1)");
  if (file.plant.kind == engine::PlantSpec::Kind::kContinuous)
    refuse("plant.continuous", "the dropping study runs a discrete plant: give plant.file (a discrete plant file with n = 3, m = 1, p = 1)");
  if (!file.buses.empty()) refuse("buses", "the dropping loop's link is point to point");
  if (!file.cpus.empty()) refuse("cpus", "no CPU in the dropping loop");
  auto out = std::make_shared<DroppingStudy>();
  out->source = file.source;
  out->plant_path = plant_file_path(file);
  try {
    out->plant = dropping::load_dropping_plant(out->plant_path);
  } catch (const std::exception& e) {
    refuse("plant.file", e.what());
  }
  const std::int64_t period_us = out->plant.plant.period_us;
  std::string sensor, controller;
  check_drop_nodes(file, period_us, sensor, controller);
  if (file.links.size() != 1) refuse("links", "the dropping loop has exactly one link, sensor -> controller");
  const engine::LinkSpec& link = file.links[0];
  if (!link.bus.empty()) refuse("links[0].bus", "the dropping loop's link is point to point");
  if (link.from != sensor) refuse("links[0].from", "the link runs from the sensor ('" + sensor + "')");
  if (link.to != controller) refuse("links[0].to", "the link runs to the controller ('" + controller + "')");
  out->link = link.name;
  out->first_seed = file.first_seed;
  out->seeds = file.seeds;
  for (std::size_t i = 0; i < file.approaches.size(); ++i) {
    out->approaches.push_back(file.approaches[i].name);
    out->kinds.push_back(file.approaches[i].kind);
  }
  for (std::size_t s = 0; s < file.scenarios.size(); ++s) {
    const engine::ScenarioSpec& x = file.scenarios[s];
    const std::string fs = at("scenarios", s);
    out->scenarios.push_back(x.name);
    dropping::RunConfig base;
    const double steps = (x.duration_s ? *x.duration_s : file.duration_s) * 1e6 / static_cast<double>(period_us);
    if (!(std::round(steps) >= 2) || std::fabs(steps - std::round(steps)) > 1e-9 * steps)
      refuse(x.duration_s ? fs + ".duration_s" : std::string("duration_s"),
             "must be a whole number (>= 2) of plant periods of " + std::to_string(period_us) + " us");
    base.steps = static_cast<std::size_t>(std::llround(steps));
    apply_drop_reference(x.reference ? &*x.reference : (file.reference ? &*file.reference : nullptr), period_us, base);
    base.link = file.link_config(link.name, &x);
    if (base.link->delay.lower_bound().count() <= 0)
      refuse(x.delays.count(link.name) != 0 ? fs + ".links." + link.name + ".delay" : std::string("links[0].delay"),
             "its smallest delay is 0: y_k would arrive at the step that took it, before the buffer's window (stamps "
             "k - T_hold ... k - 1), refused by the buffered filter as a future stamp while the unaware KF would take it");
    for (std::size_t i = 0; i < file.approaches.size(); ++i) {
      const engine::ApproachSpec& a = file.approaches[i];
      if (a.kind != "buffered" && a.kind != "unaware" && a.kind != "bernoulli")
        refuse(at("approaches", i) + ".kind", "'" + a.kind + "' (buffered, unaware, bernoulli)");
      dropping::RunConfig c = base;
      const double t_hold = drop_param(a, "t_hold");
      c.t_hold = t_hold == kDropAbsent ? 1 : static_cast<int>(t_hold);
      if (a.kind == "unaware") {
        refuse_drop_param(a, i, "t_hold");
        refuse_drop_param(a, i, "lambda");
        c.estimator = dropping::EstimatorKind::kUnaware;
        c.t_hold = 1;
        const double r = drop_param(a, "r");
        c.unaware_r = r == kDropAbsent ? out->plant.r(0, 0) : r;
      } else {
        refuse_drop_param(a, i, "r");
        c.estimator = dropping::EstimatorKind::kBuffered;
        if (a.kind == "bernoulli") {
          c.channel = dropping::ChannelKind::kBernoulli;
          const double l = drop_param(a, "lambda");
          if (l != kDropAbsent) {
            c.bernoulli_lambda = l;
          } else if (x.params_given.count("lambda") != 0) {
            c.bernoulli_lambda = x.params.at("lambda");
          } else {
            refuse(at("approaches", i) + ".params.lambda",
                   "missing: the Bernoulli channel's lambda, here or in every scenario's params.lambda (" + x.name + " has none)");
          }
        } else {
          refuse_drop_param(a, i, "lambda");
        }
      }
      if (out->runs.size() <= i) out->runs.resize(i + 1);
      out->runs[i].push_back(c);
    }
  }
  return out;
}

}  // namespace

nlohmann::json dropping_run_json(const dropping::RunConfig& c) {
  nlohmann::json j = {{"estimator", c.estimator == dropping::EstimatorKind::kBuffered ? "buffered" : "unaware"},
                      {"steps", c.steps}, {"square_wave_period_s", c.square_wave_period_s},
                      {"square_wave_amplitude", c.square_wave_amplitude}};
  if (c.estimator == dropping::EstimatorKind::kBuffered) j["t_hold"] = c.t_hold;
  if (c.estimator == dropping::EstimatorKind::kUnaware) j["r"] = c.unaware_r;
  if (c.channel == dropping::ChannelKind::kBernoulli) {
    j["channel"] = "bernoulli";
    j["lambda"] = c.bernoulli_lambda;
  } else {
    j["channel"] = "link";
    j["delay"] = c.link->delay.describe();
    j["loss"] = c.link->loss.describe();
    j["order"] = c.link->fifo ? "fifo" : "any";
  }
  return j;
}

const engine::StudySchema& dropping_schema() {
  static const engine::StudySchema schema = [] {
    engine::StudySchema s;
    s.study = "dropping";
    s.approach_kinds = {"buffered", "unaware", "bernoulli"};
    s.approach_params = {{"t_hold", 1, 8, true, false, kDropAbsent},
                         {"r", 1e-9, 1e9, false, false, kDropAbsent},
                         {"lambda", 1e-9, 1, false, false, kDropAbsent}};
    s.scenario_params = {{"lambda", 1e-9, 1, false, false, kDropAbsent}};
    return s;
  }();
  return schema;
}

std::shared_ptr<const DroppingStudy> map_dropping_study(const engine::StudyFile& file) {
  try {
    return map_drop(file);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(file.source + ":", 0) == 0) throw;
    throw InputError(file.source + ": " + what);
  }
}

void add_dropping_design(nlohmann::json& r, const DroppingStudy& s) {
  const dropping::DroppingPlant& p = s.plant;
  nlohmann::json d;
  d["plant"] = {{"name", p.plant.name}, {"file", s.plant_path}, {"period_us", p.plant.period_us}};
  nlohmann::json l = nlohmann::json::array();
  for (std::size_t i = 0; i < dropping::kN; ++i) l.push_back(p.l(0, i));
  d["L"] = {l};
  d["rho"] = p.rho;
  d["lambda_sys"] = p.lambda_sys;
  const dropping::LambdaCBracket b = dropping::lambda_c_bisection(p.mare(), p.lambda_sys, 1e-4);
  d["lambda_c_bracket"] = b.hi_converges ? nlohmann::json::array({b.lo, b.hi}) : nlohmann::json(nullptr);
  d["link"] = s.link;
  d["link_streams"] = "link/sensor/delay, link/sensor/loss";
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json e = {{"name", s.approaches[a]}, {"kind", s.kinds[a]}};
    e["per_scenario"] = nlohmann::json::array();
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) e["per_scenario"].push_back(dropping_run_json(s.runs[a][x]));
    d["approaches"].push_back(e);
  }
  r["dropping"] = d;
}

std::string describe_dropping(const nlohmann::json& r) {
  const nlohmann::json& d = r.at("dropping");
  std::ostringstream o;
  o << "dropping loop: plant " << d.at("plant").at("name").get<std::string>() << " (T = " << d.at("plant").at("period_us")
    << " us), L = " << d.at("L").dump() << ", rho(Phi) = " << d.at("rho") << ", lambda_sys = " << d.at("lambda_sys")
    << ", lambda_c in " << d.at("lambda_c_bracket").dump() << "\n";
  o << "  link " << d.at("link").get<std::string>() << " (streams " << d.at("link_streams").get<std::string>() << ")\n";
  for (const nlohmann::json& a : d.at("approaches")) {
    const nlohmann::json& c = a.at("per_scenario").at(0);
    o << "  approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>() << "): "
      << c.at("estimator").get<std::string>();
    if (c.contains("t_hold")) o << ", T_hold " << c.at("t_hold");
    if (c.contains("r")) o << ", R " << c.at("r");
    o << ", channel " << c.at("channel").get<std::string>() << "\n";
  }
  return o.str();
}

}  // namespace oneshot::study
