/// @file fuzz_study.cpp
/// @brief libFuzzer harness of the study-file parser: engine::parse_study(text, source, schema, base_dir).
///
/// Each input is parsed twice: without a schema (any approach kind, any finite parameter)
/// and with a small schema of this harness (study "fuzz": kinds, ranges, an integer and a
/// required parameter). Delay traces named in the input are read relative to a folder the
/// harness fills with one valid trace ("delays.csv").
///
/// Oracle for an accepted study: every number is finite and inside its documented range;
/// names of nodes, links, buses, approaches and scenarios are unique and node addresses
/// too; every link joins two declared nodes; covariance and weight matrices are symmetric
/// positive semidefinite (checked with Eigen's eigenvalues, independently of the parser);
/// every link of every scenario has a configuration whose delay draws are whole, finite,
/// between the model's lower bound and its cap, whose loss rate is a probability and whose
/// description holds no "nan" or "inf", whose mean (study check) is not below the lower
/// bound and whose upper bound, where the model has one, bounds every draw; the CAN response-time analysis of each bus's
/// background traffic ends with finite figures; with the schema, approach kinds are known
/// and parameters respect their range and integrality.
///
/// Then `oneshot-sim study check` on it (sim_host/study/): the resolution either refuses
/// naming a field (engine::InputError "field '…'") or gives only finite numbers (null for an
/// unbounded delay or response time); the ncs mapping (also on a third parse with the ncs
/// schema) refuses naming a field or yields one scenario per file scenario with the file's
/// legs. A fourth parse with the sod schema reaches the sod mapping (sim_host/study/
/// study_sod_map.cpp; its δt design, which runs simulations, is not called): `study check`'s
/// resolution of a sod file and the mapping either refuse naming a field or give finite figures
/// and a study of two sensors with distinct links, finite thresholds δy ≥ 0, per scenario ξ in
/// [0, 1] and at least one step, one approach per file approach with its sender and filter. A
/// plant file "networked_board.json" (study ncs's; n = 2, m = 1, p = 2 with diagonal R: one the
/// sod mapping takes) sits in the harness's folder, and inputs are parsed as if they were a file
/// there.
/// Parsed with the oneshot schema, the one-shot board's mapping (study_oneshot_map.cpp, without
/// the simulator) refuses naming a field or yields one scenario per file scenario whose job always
/// finishes before the period (release + exec < h), set-points inside the ADC range, one run option
/// per approach, a design summary of finite numbers, and with a CPU the job among its tasks.
///
/// The petc mapping (a fourth parse with the petc schema, study_petc_map.cpp; the petc plant
/// "hdd_numre.json" beside the other): it refuses naming a field or yields one design per
/// scenario (a TTS response of K finite outputs and a finite, positive ISE) and one case per
/// approach and scenario with finite thresholds ≥ 0; files of more than 5000 periods
/// (0.1 s) per scenario are not mapped (the design runs the TTS loop over K).
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "fuzz_oracle.hpp"
#include "study_fuzz_support.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_ncs_runner.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"
#include "study_oneshot_study.hpp"
#include "study_petc_study.hpp"

namespace e = oneshot::engine;
using oneshot::fuzz::require;
using oneshot::fuzz::require_finite_json;
using oneshot::fuzz::require_named;

namespace {

std::string g_base_dir;

bool finite_matrix(const oneshot::design::DenseMatrix& m) {
  for (double v : m.values)
    if (!std::isfinite(v)) return false;
  return m.values.size() == m.rows * m.cols;
}

/// Symmetric positive semidefinite within a relative tolerance (or absent).
void require_psd(const oneshot::design::DenseMatrix& m, const std::string& what) {
  if (m.rows == 0) return;
  require(m.rows == m.cols && finite_matrix(m), what + ": not a finite square matrix");
  Eigen::MatrixXd x(static_cast<Eigen::Index>(m.rows), static_cast<Eigen::Index>(m.cols));
  double scale = 0;
  for (std::size_t i = 0; i < m.rows; ++i)
    for (std::size_t j = 0; j < m.cols; ++j) {
      x(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = m(i, j);
      scale = std::fmax(scale, std::fabs(m(i, j)));
    }
  if (scale == 0) return;
  const Eigen::MatrixXd unit = x / scale;  // no overflow in the eigen-solver
  require((unit - unit.transpose()).cwiseAbs().maxCoeff() <= 1e-9, what + ": accepted, not symmetric");
  const double lowest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(unit, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
  require(lowest >= -1e-6, what + ": accepted, not positive semidefinite (eigenvalue " + std::to_string(lowest * scale) + ")");
}

void check_plant(const e::PlantSpec& p) {
  if (p.kind == e::PlantSpec::Kind::kContinuous) {
    const e::ContinuousModel& m = p.continuous;
    require(finite_matrix(m.a) && finite_matrix(m.b) && finite_matrix(m.c) && finite_matrix(m.bw), "plant: non-finite matrix");
    require(m.a.rows == m.a.cols && m.b.rows == m.a.rows && m.c.cols == m.a.rows, "plant: inconsistent shapes");
    require_psd(m.qc, "plant.continuous.Q_c");
    require_psd(m.q1c, "plant.continuous.Q1c");
    require_psd(m.q2c, "plant.continuous.Q2c");
    if (p.design) {  // the design keys: the plant file's description of the same matrices
      const oneshot::design::PlantDescription& d = *p.design;
      require(d.period_us > 0, "plant.continuous.period_us: accepted, not positive");
      require(d.n() == m.a.rows && d.m() == m.b.cols && d.p() == m.c.rows, "plant.continuous: design of another shape");
      require(d.a.values == m.a.values && d.c.values == m.c.values, "plant.continuous: design of other matrices");
      require_psd(d.measurement_covariance, "plant.continuous.measurement_covariance");
      for (std::size_t i = 0; i < d.p(); ++i)
        require(d.measurement_covariance(i, i) > 0, "plant.continuous.measurement_covariance: accepted, not positive definite");
    }
  } else if (p.kind == e::PlantSpec::Kind::kDiscrete) {
    const e::DiscreteModel& m = p.discrete;
    require(finite_matrix(m.phi) && finite_matrix(m.gamma) && finite_matrix(m.c) && finite_matrix(m.gamma_w),
            "plant: non-finite matrix");
    require(m.phi.rows == m.phi.cols && m.gamma.rows == m.phi.rows && m.c.cols == m.phi.rows, "plant: inconsistent shapes");
    require(m.period.count() > 0, "plant: non-positive period");
    require_psd(m.q, "plant.discrete.Q");
    require_psd(m.q1, "plant.discrete.Q1");
    require_psd(m.q2, "plant.discrete.Q2");
    if (p.design) {  // the design keys: the plant file of form discrete (continuous equivalent with Q1c/Q2c or a board)
      const oneshot::design::PlantDescription& d = *p.design;
      require(d.n() == m.phi.rows && d.m() == m.gamma.cols && d.p() == m.c.rows, "plant.discrete: design of another shape");
      require(!d.from_discrete || (d.continuous() && d.d2c_relative_error <= 1e-10),
              "plant.discrete: a continuous equivalent that does not sample back to Phi, Gamma");
      require_psd(d.measurement_covariance, "plant.discrete.measurement_covariance");
    }
  } else {
    require(!p.file.empty(), "plant: empty file name");
  }
}

void check_link(const e::LinkConfig& c, const std::string& what) {
  const std::string d = c.delay.describe() + " " + c.loss.describe();
  require(d.find("nan") == std::string::npos && d.find("inf") == std::string::npos, what + ": describe() " + d);
  const double rate = c.loss.loss_rate();
  require(std::isfinite(rate) && rate >= 0 && rate <= 1, what + ": loss rate " + std::to_string(rate));
  const e::Duration low = c.delay.lower_bound();
  require(low.count() >= 0, what + ": negative lower bound");
  // What `study check` prints: mean ≥ min, finite (a heavy tail's draw is clamped at its cap), max ≥ min.
  const double mean = c.delay.mean_ns();
  require(!std::isnan(mean) && mean >= static_cast<double>(low.count()) * (1 - 1e-12) - 1, what + ": mean below the lower bound");
  require(std::isfinite(mean), what + ": infinite mean");
  const std::optional<e::Duration> high = c.delay.upper_bound();
  if (high) require(*high >= low, what + ": upper bound below the lower bound");
  e::RandomStream rng(1, "fuzz");
  for (std::uint64_t k = 0; k < 16; ++k) {
    bool clamped = false;
    const e::Duration x = c.delay.draw(rng, k, clamped);
    require(x >= low, what + ": delay draw below the lower bound");
    require(x.count() >= 0, what + ": negative delay drawn");
    const bool heavy = c.delay.kind == e::DelayModel::Kind::kLognormal || c.delay.kind == e::DelayModel::Kind::kPareto;
    if (heavy) require(x <= c.delay.cap, what + ": delay draw above the cap");
    if (high) require(x <= *high, what + ": delay draw above the upper bound");
  }
}

void check_params(const std::map<std::string, double>& params, const std::vector<e::ParamSpec>* specs,
                  const std::string& what) {
  for (const auto& [name, v] : params) require(std::isfinite(v), what + "." + name + ": not finite");
  if (specs == nullptr) return;
  for (const e::ParamSpec& s : *specs) {
    if (!s.words.empty()) {  // a word parameter: never among the numbers
      require(params.count(s.name) == 0, what + "." + s.name + ": a word parameter taken as a number");
      continue;
    }
    const auto it = params.find(s.name);
    require(it != params.end(), what + ": parameter " + s.name + " missing after defaults");
    // An absent optional parameter reads its fallback, which a schema may put outside the range
    // as the mark "not given" (the dropping and sod schemas: 0 below every range).
    const bool absent_mark = !s.required && it->second == s.fallback;
    require(absent_mark || (it->second >= s.min && it->second <= s.max), what + "." + s.name + ": out of range");
    if (s.integer && !absent_mark) require(it->second == std::floor(it->second), what + "." + s.name + ": not an integer");
  }
  for (const auto& [name, v] : params) {
    bool known = false;
    for (const e::ParamSpec& s : *specs) known = known || s.name == name;
    require(known, what + ": unknown parameter " + name + " accepted");
  }
}

template <typename T, typename F>
void require_unique(const std::vector<T>& items, F name, const std::string& what) {
  std::set<std::string> seen;
  for (const T& x : items) require(seen.insert(name(x)).second, what + ": duplicate name accepted: " + name(x));
}

void check_study(const e::StudyFile& s, const e::StudySchema* schema) {
  require(std::isfinite(s.duration_s) && s.duration_s > 0 && s.duration_s <= 1e6, "duration_s out of range");
  require(s.seeds >= 2 && s.seeds <= 10'000'000, "seed count out of range");
  if (s.loops.empty()) {
    check_plant(s.plant);
  } else {  // several loops: each with its plant and three nodes of their roles, every node in one loop, links within one
    require_unique(s.loops, [](const e::LoopSpec& l) { return l.name; }, "loops");
    std::map<std::string, std::string> loop_of;
    for (const e::LoopSpec& l : s.loops) {
      check_plant(l.plant);
      require(s.node(l.sensor).role == "sensor" && s.node(l.controller).role == "controller" && s.node(l.actuator).role == "actuator",
              "loops: a node of the wrong role accepted");
      for (const std::string* n : {&l.sensor, &l.controller, &l.actuator}) require(loop_of.emplace(*n, l.name).second, "loops: a node in two loops");
    }
    for (const e::NodeSpec& n : s.nodes) require(loop_of.count(n.name) != 0, "loops: a node in no loop accepted");
    for (const e::LinkSpec& l : s.links) require(loop_of.at(l.from) == loop_of.at(l.to), "loops: a link across loops accepted");
  }
  require_unique(s.nodes, [](const e::NodeSpec& n) { return n.name; }, "nodes");
  std::set<int> addresses;
  for (const e::NodeSpec& n : s.nodes) {
    require(addresses.insert(n.address).second, "node address used twice");
    require(n.mode == "arrival" || n.period.count() > 0, "timer node without a period");
    if (n.trigger) {
      for (double d : n.trigger->delta) require(std::isfinite(d) && d >= 0, "trigger delta");
      require(std::isfinite(n.trigger->sigma) && std::isfinite(n.trigger->mtm_delta), "MTM parameters");
    }
  }
  require_unique(s.links, [](const e::LinkSpec& l) { return l.name; }, "links");
  require_unique(s.buses, [](const e::BusSpec& b) { return b.config.name; }, "buses");
  require_unique(s.approaches, [](const e::ApproachSpec& a) { return a.name; }, "approaches");
  require_unique(s.scenarios, [](const e::ScenarioSpec& x) { return x.name; }, "scenarios");
  for (const e::LinkSpec& l : s.links) {
    s.node(l.from);  // throws when the parser let an unknown node through (crash: a finding)
    s.node(l.to);
    require(l.from != l.to, "link from a node to itself");
    if (l.bus.empty()) check_link(s.link_config(l.name), "links." + l.name);
  }
  for (const e::ScenarioSpec& x : s.scenarios) {
    if (x.duration_s) require(std::isfinite(*x.duration_s) && *x.duration_s > 0, "scenario duration");
    check_params(x.params, schema != nullptr ? &schema->scenario_params : nullptr, "scenarios." + x.name);
    for (const e::LinkSpec& l : s.links)
      if (l.bus.empty()) check_link(s.link_config(l.name, &x), "scenarios." + x.name + ".links." + l.name);
  }
  for (const e::ApproachSpec& a : s.approaches) {
    check_params(a.params, schema != nullptr ? &schema->approach_params : nullptr, "approaches." + a.name);
    for (const auto& [key, word] : a.words) {  // a word parameter: one of its spec's words
      bool known = schema == nullptr;  // no schema: any word
      if (schema != nullptr)
        for (const e::ParamSpec& p : schema->approach_params)
          for (const std::string& w : p.words) known = known || (p.name == key && w == word);
      require(known, "approaches." + a.name + "." + key + ": word '" + word + "' accepted");
    }
    if (schema != nullptr) {
      bool known = false;
      for (const std::string& k : schema->approach_kinds) known = known || k == a.kind;
      require(known, "unknown approach kind accepted: " + a.kind);
    }
  }
  for (const e::BusSpec& b : s.buses) {
    if (b.background.empty() || b.background.size() > 64) continue;
    const std::vector<e::CanStreamBound> r = e::can_response_times(b.background, b.config);
    require(r.size() == b.background.size(), "CAN analysis: one bound per stream");
    for (const e::CanStreamBound& x : r) {
      require(x.transmission.count() > 0, "CAN analysis: transmission time");
      if (x.bounded) require(x.response >= x.transmission && x.response.count() > 0, "CAN analysis: response time");
      require(!x.schedulable || x.bounded, "CAN analysis: schedulable without a bound");
    }
  }
}

void check_study_check(const e::StudyFile& s) {
  try {
    require_finite_json(oneshot::study::resolve_study(s), "resolution", "study check");
  } catch (const e::InputError& x) {
    require_named(x, "study check");
  }
  try {
    const oneshot::study::NcsStudy n = oneshot::study::map_ncs_study(s);
    require(n.scenarios.size() == s.scenarios.size() && n.approaches.size() == s.approaches.size(), "ncs mapping: sizes");
    for (const auto& sc : n.scenarios) require(sc.legs.size() + sc.bus_legs.size() == n.links.size(), "ncs mapping: legs");
  } catch (const e::InputError& x) {
    require_named(x, "ncs mapping");
  }
}

/// A file parsed with the sod schema: `study check`'s resolution and the sod mapping.
void check_sod(const e::StudyFile& s) {
  try {
    require_finite_json(oneshot::study::resolve_sod_study(s), "resolution", "sod study check");
  } catch (const e::InputError& x) {
    require_named(x, "sod study check");
  }
  try {
    const std::shared_ptr<const oneshot::study::SodStudy> m = oneshot::study::map_sod_study(s);
    require(m->approaches.size() == s.approaches.size() && m->scenarios.size() == s.scenarios.size(), "sod mapping: sizes");
    require(m->sensors[0] != m->sensors[1] && m->links[0] != m->links[1] && !m->links[0].empty() && !m->links[1].empty(),
            "sod mapping: two sensors, one link each");
    for (double d : m->delta_y) require(std::isfinite(d) && d >= 0, "sod mapping: delta_y");
    for (const oneshot::study::SodScenario& x : m->scenarios)
      require(x.loss >= 0 && x.loss <= 1 && x.steps >= 1 && std::isfinite(x.amplitude), "sod mapping: scenario");
    for (const oneshot::study::SodApproach& a : m->approaches) require(a.every >= 1 && a.mu > 1, "sod mapping: approach");
  } catch (const e::InputError& x) {
    require_named(x, "sod mapping");
  }
}

void check_oneshot_mapping(const e::StudyFile& s) {
  try {
    const std::shared_ptr<oneshot::study::OneShotFileStudy> o = oneshot::study::map_oneshot_file(s);
    require(o->scenarios.size() == s.scenarios.size() && o->options.size() == s.approaches.size(), "oneshot mapping: sizes");
    for (const oneshot::sim::Scenario& x : o->scenarios) {
      require(x.jitter.max_busy_us() < o->plant.period_us, "oneshot mapping: the job past its period");
      require(x.duration_s * 1e6 >= static_cast<double>(o->plant.period_us), "oneshot mapping: shorter than a period");
      require(x.amplitude_volts < o->plant.board.adc_max_volts[0] && -x.amplitude_volts > o->plant.board.adc_min_volts[0],
              "oneshot mapping: set-point outside the ADC range");
    }
    require(!o->cpu || o->job_task < o->cpu->tasks.size(), "oneshot mapping: the job on its CPU");
    nlohmann::json r;
    oneshot::study::add_oneshot_design(r, *o);
    require_finite_json(r, "oneshot design", "oneshot mapping");
  } catch (const e::InputError& x) {
    require_named(x, "oneshot mapping");
  }
}

/// The petc mapping: a refusal naming a field, or the designs and cases (see the file's brief).
void check_petc_mapping(const e::StudyFile& s) {
  double longest = s.duration_s;
  for (const e::ScenarioSpec& x : s.scenarios)
    if (x.duration_s) longest = std::fmax(longest, *x.duration_s);
  if (longest > 0.1) return;  // bounded: K ≤ 5000 periods of the petc plant's 20 us
  try {
    const std::shared_ptr<const oneshot::study::PetcStudy> p = oneshot::study::map_petc_study(s);
    require(p->setups.size() == s.scenarios.size() && p->runs.size() == s.approaches.size(), "petc mapping: sizes");
    for (const auto& st : p->setups) {
      require(st.y_tts.size() == st.opt.steps && std::isfinite(st.ise) && st.ise > 0, "petc mapping: TTS response");
      for (double y : st.y_tts) require(std::isfinite(y), "petc mapping: a non-finite TTS output");
    }
    for (const auto& per : p->runs) {
      require(per.size() == s.scenarios.size(), "petc mapping: one case per scenario");
      for (const auto& c : per)
        for (double t : {c.sigma_s, c.delta_s, c.sigma_c, c.delta_c}) require(std::isfinite(t) && t >= 0, "petc mapping: threshold");
    }
  } catch (const e::InputError& x) {
    require_named(x, "petc mapping");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  g_base_dir = oneshot::fuzz::study_folder(ONESHOT_NCS_PLANT_FILE);
  std::filesystem::copy_file(ONESHOT_PETC_PLANT_FILE, g_base_dir + "/hdd_numre.json", std::filesystem::copy_options::overwrite_existing);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  static const e::StudySchema schema = {
      "fuzz",
      {"ideal", "kalman"},
      {{"gain", 0, 10, false, false, 1}, {"horizon", 1, 100, true, false, 10}},
      {{"amplitude", 0, 5, false, true, 0}, {"steps", 0, 1000, true, false, 0}}};
  const std::string source = g_base_dir + "/fuzz.json";  // plant files resolve in the harness's folder
  for (const e::StudySchema* sc : {static_cast<const e::StudySchema*>(nullptr), &schema, &oneshot::study::ncs_schema(),
                                   &oneshot::study::sod_schema(),
                                   &oneshot::study::petc_schema()}) {
    e::StudyFile s;
    try {
      s = e::parse_study(text, source, sc, g_base_dir);
    } catch (const e::InputError&) {
      continue;  // refused with a message: fine
    }
    if (sc == &oneshot::study::petc_schema()) {  // its absent approach params read a sentinel below their range
      check_study(s, nullptr);
      check_petc_mapping(s);
      continue;
    }
    check_study(s, sc);
    if (sc != &schema) check_study_check(s);
    if (sc == &oneshot::study::sod_schema()) check_sod(s);
  }
  try {  // the one-shot board's mapping, on the file parsed with its schema
    check_oneshot_mapping(e::parse_study(text, source, &oneshot::study::oneshot_schema(), g_base_dir));
  } catch (const e::InputError&) {
    // refused by the parser with a message: fine
  }
  return 0;
}
