/// @file study_oneshot_map.cpp
/// @brief A "study": "oneshot" file mapped onto the one-shot board loop of Table I (see
///        study_oneshot_study.hpp): the schema, the mapping and its refusals, the design and the
///        jitter summary that `study check` prints.
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/design_report.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_fields.hpp"
#include "study_oneshot_study.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {

namespace {

using engine::InputError;

/// Table I's approach kinds (approach.hpp), in table order.
const char* const kOneShotKinds[] = {"A", "B", "C", "D", "E"};
/// The scenario's job-timing params: every one 0 (their default) is no jitter (model none).
const char* const kJitterParams[] = {"release_min_us", "release_max_us", "exec_min_us", "exec_max_us"};

/// The approach's word parameter `key`, or `fallback` when the file does not give it.
std::string word(const engine::ApproachSpec& a, const char* key, const char* fallback) {
  const auto it = a.words.find(key);
  return it == a.words.end() ? fallback : it->second;
}

/// The run options of approach `i` (kind A–E, its words; table1's defaults otherwise) and their
/// settings as JSON (the words by their names: simulation.cpp's to_string(), which the mapping
/// does not link so that the fuzz harness reaches it).
sim::RunOptions approach_options(const engine::ApproachSpec& a, std::size_t i, const design::DesignResult& d, nlohmann::json& settings) {
  sim::RunOptions o;
  bool known = false;
  for (sim::Approach x : sim::kAllApproaches)
    if (a.kind.size() == 1 && a.kind[0] == sim::info(x).letter) {
      o.approach = x;
      known = true;
    }
  if (!known) refuse(at("approaches", i) + ".kind", "'" + a.kind + "' (A, B, C, D, E: Table I's approaches)");
  if (o.approach == sim::Approach::kE && !d.deadbeat)
    refuse(at("approaches", i) + ".kind", "'" + a.kind + "': the plant has no deadbeat observer (" + d.deadbeat_unavailable_reason + ")");
  const std::string format = word(a, "number_format", "float"), disc = word(a, "discretizer", "table");
  const std::string noise = word(a, "noise_model", "exact"), pwm = word(a, "pwm_update", "immediate");
  o.format = format == "double" ? sim::NumberFormat::kDouble : sim::NumberFormat::kFloat;
  o.discretizer = disc == "generic" ? sim::DiscretizerKind::kGeneric : disc == "nearest" ? sim::DiscretizerKind::kNearest : sim::DiscretizerKind::kTable;
  o.noise = noise == "constant" ? oneshot::NoiseModel::kConstant : oneshot::NoiseModel::kExact;
  o.board.update = pwm == "period" ? sim::PwmUpdate::kNextPeriod : sim::PwmUpdate::kImmediate;
  settings = {{"kind", a.kind}, {"description", sim::info(o.approach).description}, {"jitter", sim::info(o.approach).jitter},
              {"number_format", format}, {"discretizer", disc}, {"noise_model", noise}, {"pwm_update", pwm}};
  return o;
}

/// Checks the one node (the board: one MCU samples, computes and actuates): role controller, a
/// timer at the plant's period without offset nor trigger.
const engine::NodeSpec& check_board_node(const engine::StudyFile& file, std::int64_t period_us) {
  if (file.nodes.size() != 1)
    refuse("nodes", "the one-shot board is one node (role controller: its MCU samples, computes and actuates), not " +
                        std::to_string(file.nodes.size()));
  const engine::NodeSpec& n = file.nodes[0];
  if (n.role != "controller") refuse("nodes[0].role", "'" + n.role + "': the board's node is the controller (it samples and actuates itself)");
  if (n.mode != "timer") refuse("nodes[0].mode", "'" + n.mode + "': the board's job is released by its timer every period");
  if (n.period.count() != period_us * 1000) refuse("nodes[0].period_us", "must be the plant's period " + std::to_string(period_us) + " us");
  if (n.clock_offset.count() != 0) refuse("nodes[0].clock_offset_us", "must be 0 (period k starts at k h)");
  if (n.trigger) refuse("nodes[0].trigger", "the board samples every period (no trigger)");
  return n;
}

/// The file's CPU `n.cpu` with the node's job added as the periodic task `n.name` (arrival k·h,
/// deadline h unless given); refused when its worst-case response can reach the period.
void map_cpu(const engine::StudyFile& file, const engine::NodeSpec& n, std::int64_t period_us, OneShotFileStudy& out) {
  for (std::size_t c = 0; c < file.cpus.size(); ++c)
    if (file.cpus[c].name != n.cpu) refuse(at("cpus", c), "'" + file.cpus[c].name + "': no job of the board runs on it (only nodes[0].cpu)");
  if (n.cpu.empty()) {
    if (!file.cpus.empty()) refuse("cpus", "the board's job runs on no CPU (give nodes[0].cpu and nodes[0].job, or no cpus)");
    return;
  }
  engine::cpu::TaskSet set = file.cpus.at(0);
  engine::cpu::TaskSpec job = *n.job;
  job.name = n.name;
  job.external = false;
  job.sporadic = false;
  job.period = engine::from_us(period_us);
  job.max_interarrival = job.period;
  job.offset = engine::Duration{0};
  if (job.deadline.count() == 0) job.deadline = job.period;
  set.tasks.push_back(job);
  out.job_task = set.tasks.size() - 1;
  const engine::cpu::Analysis a = engine::cpu::analyze(set);
  const engine::cpu::TaskBound& b = a.tasks.at(out.job_task);
  // Release + execution in whole µs must stay below h (validate_scenario): WCRT ≤ h − 1 µs.
  if (!b.bounded || b.wcrt > engine::from_us(period_us - 1))
    refuse("nodes[0].job", std::string("its worst-case response on CPU '") + set.name + "' is " +
                               (b.bounded ? std::to_string(static_cast<double>(b.wcrt.count()) * 1e-3) + " us" : "unbounded") +
                               ", not below the period " + std::to_string(period_us) +
                               " us: the job of period k must prepare u before the timer applies it at (k+1) h");
  // Every job completes (its timing is the run's): none aborted at a deadline before its end.
  if (job.overrun == engine::cpu::OverrunPolicy::kAbort && b.wcrt > job.deadline)
    refuse("nodes[0].job.deadline_us", "the job may be aborted at it (overrun abort, worst-case response " +
                                           std::to_string(static_cast<double>(b.wcrt.count()) * 1e-3) +
                                           " us): the board's job must complete to prepare u");
  out.cpu = std::move(set);
}

/// Scenario `i`'s set-point, duration and jitter; refusals name the field.
sim::Scenario map_scenario(const engine::StudyFile& file, std::size_t i, const OneShotFileStudy& out) {
  const engine::ScenarioSpec& x = file.scenarios[i];
  const std::string fs = at("scenarios", i);
  const design::PlantDescription& plant = out.plant;
  const std::int64_t h = plant.period_us;
  if (x.reference)
    refuse(fs + ".reference", "the board's set-point is a random step every change period: give params.amplitude_volts and params.change_period_s");
  if (!x.delays.empty() || !x.losses.empty()) refuse(fs + ".links", "the board has no links");
  sim::Scenario s;
  s.name = x.name;
  s.duration_s = x.duration_s ? *x.duration_s : file.duration_s;
  s.amplitude_volts = x.params.at("amplitude_volts");
  s.change_period_s = x.params.at("change_period_s");
  const auto p = [&](const char* k) { return static_cast<std::int32_t>(x.params.at(k)); };
  if (out.cpu) {
    for (const char* k : kJitterParams)
      if (x.params_given.count(k) != 0)
        refuse(fs + ".params." + k, "the board's job runs on CPU '" + out.cpu->name + "': its timing is that CPU's schedule");
    s.jitter.kind = sim::JitterModel::Kind::kTrace;  // filled per seed (oneshot_run_scenario())
    s.jitter.trace_path = "CPU " + out.cpu->name + " schedule";
  } else if (p("release_min_us") != 0 || p("release_max_us") != 0 || p("exec_min_us") != 0 || p("exec_max_us") != 0) {
    s.jitter.kind = sim::JitterModel::Kind::kUniform;
    s.jitter.release_min_us = p("release_min_us");
    s.jitter.release_max_us = p("release_max_us");
    s.jitter.exec_min_us = p("exec_min_us");
    s.jitter.exec_max_us = p("exec_max_us");
    if (s.jitter.release_max_us < s.jitter.release_min_us) refuse(fs + ".params.release_max_us", "below release_min_us");
    if (s.jitter.exec_max_us < s.jitter.exec_min_us) refuse(fs + ".params.exec_max_us", "below exec_min_us");
    if (static_cast<std::int64_t>(s.jitter.release_max_us) + s.jitter.exec_max_us >= h)
      refuse(fs + ".params.release_max_us", "release_max_us + exec_max_us must stay below the period " + std::to_string(h) +
                                                " us (the job of period k prepares u for (k+1) h)");
  }
  for (std::size_t o = 0; o < plant.p(); ++o)
    if (s.amplitude_volts >= plant.board.adc_max_volts[o] || -s.amplitude_volts <= plant.board.adc_min_volts[o])
      refuse(fs + ".params.amplitude_volts", "outside the ADC range (" + std::to_string(plant.board.adc_min_volts[o]) + ", " +
                                                 std::to_string(plant.board.adc_max_volts[o]) + ") V");
  const std::string fd = x.duration_s ? fs + ".duration_s" : std::string("duration_s");
  if (s.duration_s * 1e6 < static_cast<double>(h)) refuse(fd, "shorter than one period of " + std::to_string(h) + " us");
  if (s.duration_s / s.change_period_s > sim::kMaxSetpointChanges)
    refuse(fs + ".params.change_period_s", "more than 10^7 set-point changes in one run");
  sim::Scenario checked = s;
  if (out.cpu) checked.jitter.kind = sim::JitterModel::Kind::kNone;  // its trace is checked per seed
  try {
    sim::validate_scenario(checked, plant);
  } catch (const sim::ScenarioError& e) {
    refuse(fs, e.what());
  }
  return s;
}

std::shared_ptr<OneShotFileStudy> map_oneshot(const engine::StudyFile& file) {
  if (file.study != "oneshot") refuse("study", "'" + file.study + "' is not 'oneshot'");
  if (!file.loops.empty()) refuse("loops", "the one-shot study runs one board per file");
  if (!file.links.empty()) refuse("links", "the one-shot board has no links: one MCU samples, computes and actuates");
  if (!file.buses.empty()) refuse("buses", "the one-shot board has no bus");
  if (file.reference) refuse("reference", "the board's set-point is a random step every change period: give scenarios[].params.amplitude_volts and change_period_s");
  auto out = std::make_shared<OneShotFileStudy>();
  out->source = file.source;
  if (file.plant.kind == engine::PlantSpec::Kind::kDiscrete || (file.plant.kind == engine::PlantSpec::Kind::kContinuous && !file.plant.design))
    refuse(file.plant.kind == engine::PlantSpec::Kind::kDiscrete ? "plant.discrete" : "plant.continuous",
           "the one-shot board runs a continuous plant with its board (PWM, ADC) and design keys: give plant.file "
           "(e.g. lut_gen/plants/reference_board.json)");
  out->plant_field = file.plant.kind == engine::PlantSpec::Kind::kFile ? "plant.file" : "plant.continuous";
  try {  // what SimContext::from_plant() requires (map_oneshot_study() then builds it)
    if (file.plant.kind == engine::PlantSpec::Kind::kFile) {
      out->plant_path = plant_file_path(file);
      out->plant = design::load_plant_file(out->plant_path);
    } else {
      out->plant_path = "(inline continuous plant)";
      out->plant = *file.plant.design;
    }
    design::require_continuous_board_and_table(out->plant, "the one-shot harness");
    out->design = design::synthesize(out->plant);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    refuse(out->plant_field, e.what());
  }
  if (!out->design.tracking)
    refuse(out->plant_field, "the harness needs set-point feed-forward (as many outputs as inputs and a unique equilibrium)");
  const std::int64_t h = out->plant.period_us;
  const engine::NodeSpec& n = check_board_node(file, h);
  out->node = n.name;
  map_cpu(file, n, h, *out);
  out->first_seed = file.first_seed;
  out->seeds = file.seeds;
  for (std::size_t i = 0; i < file.approaches.size(); ++i) {
    out->approaches.push_back(file.approaches[i].name);
    out->kinds.push_back(file.approaches[i].kind);
    nlohmann::json settings;
    out->options.push_back(approach_options(file.approaches[i], i, out->design, settings));
    settings["name"] = file.approaches[i].name;
    out->settings.push_back(settings);
  }
  for (std::size_t i = 0; i < file.scenarios.size(); ++i) out->scenarios.push_back(map_scenario(file, i, *out));
  return out;
}

}  // namespace

const engine::StudySchema& oneshot_schema() {
  static const engine::StudySchema schema = [] {
    engine::StudySchema s;
    s.study = "oneshot";
    s.approach_kinds.assign(std::begin(kOneShotKinds), std::end(kOneShotKinds));
    s.approach_params = {{"number_format", 0, 0, false, false, 0, {"float", "double"}},
                         {"discretizer", 0, 0, false, false, 0, {"table", "nearest", "generic"}},
                         {"noise_model", 0, 0, false, false, 0, {"exact", "constant"}},
                         {"pwm_update", 0, 0, false, false, 0, {"immediate", "period"}}};
    s.scenario_params = {{"amplitude_volts", 0, 100, false, false, 0.2},
                         {"change_period_s", 0.001, 1e6, false, false, 1.0}};
    for (const char* k : kJitterParams) s.scenario_params.push_back({k, 0, 60'000'000, true, false, 0});
    return s;
  }();
  return schema;
}

std::shared_ptr<OneShotFileStudy> map_oneshot_file(const engine::StudyFile& file) {
  try {
    return map_oneshot(file);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.rfind(file.source + ":", 0) == 0) throw;
    throw InputError(file.source + ": " + what);
  }
}

void add_oneshot_design(nlohmann::json& r, const OneShotFileStudy& s) {
  const design::PlantDescription& p = s.plant;
  const std::int64_t h = p.period_us;
  nlohmann::json d;
  d["plant"] = {{"name", p.name}, {"file", s.plant_path}, {"period_us", h}};
  const nlohmann::json dj = design::design_json(p, s.design);
  for (const char* k : {"L", "kalman_gain"})
    if (dj.contains(k)) d["design"][k] = dj.at(k);
  d["node"] = s.node;
  d["approaches"] = s.settings;
  if (s.cpu) {
    const engine::cpu::Analysis a = engine::cpu::analyze(*s.cpu);
    const engine::cpu::TaskBound& b = a.tasks.at(s.job_task);
    const auto us = [](engine::Duration t) { return static_cast<double>(t.count()) * 1e-3; };
    d["cpu"] = {{"name", s.cpu->name}, {"utilization", s.cpu->utilization()}, {"job", s.node},
                {"job_priority", s.cpu->tasks[s.job_task].priority}, {"job_bcrt_us", us(b.bcrt)}, {"job_wcrt_us", us(b.wcrt)},
                {"release_us", {us(b.sampling_latency_min), us(b.sampling_latency_max)}},
                {"tau_one_shot_us", {static_cast<double>(h) - us(b.sampling_latency_max), static_cast<double>(h) - us(b.sampling_latency_min)}},
                {"tasks", engine::cpu::task_set_json(*s.cpu)}};
  }
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    const sim::Scenario& c = s.scenarios[x];
    nlohmann::json e = {{"name", c.name}, {"duration_s", c.duration_s}, {"amplitude_volts", c.amplitude_volts},
                        {"change_period_s", c.change_period_s},
                        {"jitter", s.cpu ? "CPU " + s.cpu->name + " schedule (per seed)" : c.jitter.describe()}};
    if (c.jitter.kind == sim::JitterModel::Kind::kUniform) {
      e["release_us"] = {c.jitter.release_min_us, c.jitter.release_max_us};
      e["exec_us"] = {c.jitter.exec_min_us, c.jitter.exec_max_us};
      e["tau_one_shot_us"] = {h - c.jitter.release_max_us, h - c.jitter.release_min_us};
    } else if (c.jitter.kind == sim::JitterModel::Kind::kNone) {
      e["release_us"] = {0, 0};
      e["exec_us"] = {0, 0};
      e["tau_one_shot_us"] = {h, h};
    }
    d["scenarios"].push_back(e);
  }
  r["oneshot"] = d;
}

std::string describe_oneshot(const nlohmann::json& r) {
  const nlohmann::json& d = r.at("oneshot");
  std::ostringstream o;
  o << "one-shot board: plant " << d.at("plant").at("name").get<std::string>() << " (h = " << d.at("plant").at("period_us")
    << " us), node " << d.at("node").get<std::string>() << " samples, computes and actuates";
  if (d.contains("design"))
    o << ", L = " << d.at("design").value("L", nlohmann::json()).dump() << ", K = " << d.at("design").value("kalman_gain", nlohmann::json()).dump();
  o << "\n";
  for (const nlohmann::json& a : d.at("approaches"))
    o << "  approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>() << ": "
      << a.at("description").get<std::string>() << "), " << a.at("number_format").get<std::string>() << ", "
      << a.at("discretizer").get<std::string>() << ", noise " << a.at("noise_model").get<std::string>() << ", pwm " << a.at("pwm_update").get<std::string>() << "\n";
  if (d.contains("cpu")) {
    const nlohmann::json& c = d.at("cpu");
    o << "  job on CPU " << c.at("name").get<std::string>() << " (U = " << c.at("utilization") << ", priority "
      << c.at("job_priority") << "): response [" << c.at("job_bcrt_us") << ", " << c.at("job_wcrt_us") << "] us, release "
      << c.at("release_us").dump() << " us, one-shot tau " << c.at("tau_one_shot_us").dump() << " us (the schedule's, per seed)\n";
  }
  for (const nlohmann::json& x : d.at("scenarios")) {
    o << "  scenario " << x.at("name").get<std::string>() << ": " << x.at("duration_s") << " s, set-point +-"
      << x.at("amplitude_volts") << " V every " << x.at("change_period_s") << " s, jitter " << x.at("jitter").get<std::string>();
    if (x.contains("tau_one_shot_us")) o << ", one-shot tau " << x.at("tau_one_shot_us").dump() << " us";
    o << "\n";
  }
  return o.str();
}

}  // namespace oneshot::study
