/// @file plant_description.cpp
/// @brief Parsing and validation of plant description files: the dynamics of each form.
#include "oneshot/design/plant_description.hpp"

#include <cmath>

#include "oneshot/design/zoh_inverse.hpp"
#include "plant_json_reader.hpp"
#include "plant_parts.hpp"

namespace oneshot::design {
namespace {

using nlohmann::json;
using detail::Checker;

/// Refuses a dimension beyond its limit, naming the limit.
void within_limit(const Checker& check, const std::string& field, std::size_t value, std::size_t limit,
                  const char* what, const char* limit_name) {
  if (value > limit) {
    check.fail(field, std::to_string(value) + " " + what + " exceed the supported maximum of " +
                          std::to_string(limit) + " (" + limit_name + ", firmware/core/include/oneshot/dimension_limits.hpp)");
  }
}

/// Continuous (A, B) or discrete (Phi, Gamma) dynamics, C and B_w.
void parse_matrices(const json& root, PlantDescription& p, const Checker& check) {
  const bool cont = p.continuous();
  const char* ka = cont ? "A" : "Phi";
  const char* kb = cont ? "B" : "Gamma";
  const std::vector<std::string> others = cont ? std::vector<std::string>{"Phi", "Gamma"}
                                               : std::vector<std::string>{"A", "B"};
  for (const std::string& other : others) {
    if (root.contains(other)) {
      check.fail(other, std::string("belongs to the ") + (cont ? "discrete" : "continuous") + " form; this plant is " +
                            to_string(p.form) + " (field 'form')");
    }
  }
  DenseMatrix a = check.matrix(root, ka, "");
  const std::size_t n = a.rows;
  check.shape(a, ka, n, n, std::string(ka) + " must be square");
  within_limit(check, ka, n, kMaxStates, "states", "kMaxStates");
  DenseMatrix b = check.matrix(root, kb, "");
  if (b.rows != n) check.shape(b, kb, n, b.cols, "one row per state");
  within_limit(check, kb, b.cols, kMaxInputs, "inputs", "kMaxInputs");
  p.c = check.matrix(root, "C", "");
  if (p.c.cols != n) check.shape(p.c, "C", p.c.rows, n, "one column per state");
  within_limit(check, "C", p.c.rows, kMaxOutputs, "outputs", "kMaxOutputs");
  p.inputs = check.names(root, "inputs", b.cols, "u");
  if (cont) {
    p.a = std::move(a);
    p.b = std::move(b);
  } else {
    p.phi = std::move(a);
    p.gamma = std::move(b);
  }
  if (root.contains("B_w")) {
    p.b_w = check.matrix(root, "B_w", "");
    if (p.b_w.rows != n) check.shape(p.b_w, "B_w", n, p.b_w.cols, "one row per state");
    within_limit(check, "B_w", p.b_w.cols, kMaxDisturbances, "disturbance inputs", "kMaxDisturbances");
  }
}

/// The section's name: an identifier (it prefixes the names of the section's states).
std::string section_name(const json& s, const std::string& path, const Checker& check) {
  const std::string name = check.optional_string(s, "name", path + ".");
  if (!detail::is_identifier(name)) {
    check.fail(path + ".name", "must be an identifier ([A-Za-z_][A-Za-z0-9_]*): it names the section's states");
  }
  return name;
}

/// A 2nd-order continuous section: {name, numerator, denominator [1, a1, a0]} or
/// {name, gain, frequency_hz, damping} (gain·ω²/(s² + 2ζωs + ω²)).
ContinuousSection parse_continuous_section(const json& s, const std::string& path, const Checker& check) {
  if (!s.is_object()) check.fail(path, "must be an object");
  ContinuousSection c;
  c.name = section_name(s, path, check);
  if (s.contains("frequency_hz")) {
    check.only_keys(s, path + ".", {"name", "gain", "frequency_hz", "damping"});
    const double f = check.number_in(s, "frequency_hz", path + ".", 1e-9, 1e12);
    const double zeta = check.number_in(s, "damping", path + ".", 0, 1e3);
    const double k = check.number(check.require(s, "gain", path + "."), path + ".gain");
    const double w = 2.0 * 3.14159265358979323846 * f;
    c.numerator = k * w * w;
    c.a1 = 2.0 * zeta * w;
    c.a0 = w * w;
  } else {
    check.only_keys(s, path + ".", {"name", "numerator", "denominator"});
    c.numerator = check.number(check.require(s, "numerator", path + "."), path + ".numerator");
    const std::vector<double> den = check.vector_of(s, "denominator", path + ".", 3);
    if (den[0] != 1.0) check.fail(path + ".denominator", "must be monic: [1, a1, a0]");
    if (!(den[2] > 0)) check.fail(path + ".denominator", "a0 must be positive (omega_n = sqrt(a0))");
    c.a1 = den[1];
    c.a0 = den[2];
  }
  return c;
}

/// A discrete biquad: {name, notch: {frequency_hz, alpha, beta}} or {name, numerator [b0, b1, b2],
/// denominator [1, a1, a2]}.
DiscreteSection parse_discrete_section(const json& s, const std::string& path, double period_s, const Checker& check) {
  if (!s.is_object()) check.fail(path, "must be an object");
  const std::string name = section_name(s, path, check);
  if (s.contains("notch")) {
    check.only_keys(s, path + ".", {"name", "notch"});
    const json& nt = check.object(s, "notch", path + ".");
    const std::string np = path + ".notch.";
    check.only_keys(nt, np, {"frequency_hz", "alpha", "beta"});
    const double f = check.number_in(nt, "frequency_hz", np, 0, 0.5 / period_s);
    const double alpha = check.number_in(nt, "alpha", np, 0, 1e3);
    const double beta = check.number_in(nt, "beta", np, 0, 1.0 - 1e-12);
    return notch_section(name, f, alpha, beta, period_s);
  }
  check.only_keys(s, path + ".", {"name", "numerator", "denominator"});
  const std::vector<double> num = check.vector_of(s, "numerator", path + ".", 3);
  const std::vector<double> den = check.vector_of(s, "denominator", path + ".", 3);
  if (den[0] != 1.0) check.fail(path + ".denominator", "must be monic: [1, a1, a2]");
  return DiscreteSection{name, num[0], num[1], num[2], den[1], den[2]};
}

/// The "sections" object → spec, realized into Φ, Γ, C, B_w, C̄.
void parse_sections(const json& root, PlantDescription& p, const Checker& check) {
  for (const char* k : {"A", "B", "Phi", "Gamma", "C", "B_w", "states"})
    if (root.contains(k)) check.fail(k, "is generated from 'sections' in the sections form; remove it");
  const json& sec = check.object(root, "sections", "");
  check.only_keys(sec, "sections.", {"continuous", "discrete", "disturbance"});
  const double t = static_cast<double>(p.period_us) * 1e-6;
  SectionsDescription& spec = p.sections;
  for (const char* key : {"continuous", "discrete"}) {
    if (!sec.contains(key)) continue;
    const json& list = sec[key];
    if (!list.is_array()) check.fail(std::string("sections.") + key, "must be an array of sections");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string path = std::string("sections.") + key + "[" + std::to_string(i) + "]";
      if (key[0] == 'c') spec.continuous.push_back(parse_continuous_section(list[i], path, check));
      else spec.discrete.push_back(parse_discrete_section(list[i], path, t, check));
    }
  }
  if (spec.continuous.empty()) check.fail("sections.continuous", "needs at least one continuous section (strictly proper plant)");
  if (sec.contains("disturbance")) {
    const json& d = check.object(sec, "disturbance", "sections.");
    const std::string dp = "sections.disturbance.";
    const std::string reading = check.optional_string(d, "reading", dp);
    if (reading == "oscillator") {
      check.only_keys(d, dp, {"reading", "frequency_rad_s", "input_gain", "output_gain"});
      spec.disturbance.reading = DisturbanceReading::kOscillator;
      spec.disturbance.frequency_rad_s = check.number_in(d, "frequency_rad_s", dp, 1e-12, 1e12);
      spec.disturbance.input_gain = check.number(check.require(d, "input_gain", dp), dp + "input_gain");
      spec.disturbance.output_gain = check.number(check.require(d, "output_gain", dp), dp + "output_gain");
    } else if (reading == "literal") {
      check.only_keys(d, dp, {"reading", "A_d", "B_d", "C_d"});
      spec.disturbance.reading = DisturbanceReading::kLiteral;
      spec.disturbance.a_d = check.matrix(d, "A_d", dp);
      const std::size_t nd = spec.disturbance.a_d.rows;
      check.shape(spec.disturbance.a_d, dp + "A_d", nd, nd, "square");
      spec.disturbance.b_d = check.matrix(d, "B_d", dp);
      check.shape(spec.disturbance.b_d, dp + "B_d", nd, spec.disturbance.b_d.cols, "one row per disturbance state");
      spec.disturbance.c_d = check.matrix(d, "C_d", dp);
      check.shape(spec.disturbance.c_d, dp + "C_d", 1, nd, "one row (the input), one column per disturbance state");
    } else {
      check.fail(dp + "reading", "must be \"oscillator\" or \"literal\"");
    }
  }
  const std::size_t states = 2 * (spec.continuous.size() + spec.discrete.size()) +
                             (spec.disturbance.reading == DisturbanceReading::kNone ? 0
                              : spec.disturbance.reading == DisturbanceReading::kOscillator ? 2
                                                                                          : spec.disturbance.a_d.rows);
  within_limit(check, "sections", states, kMaxStates, "states", "kMaxStates");
  p.has_sections = true;
  SectionsRealization r;
  try {
    r = realize_sections(spec, t);
  } catch (const std::exception& e) {
    check.fail("sections", e.what());
  }
  p.phi = r.phi;
  p.gamma = r.gamma;
  p.c = r.c;
  p.b_w = r.b_w;
  p.c_bar = r.c_bar;
  p.exogenous_states = r.exogenous_states;
  p.states = r.state_names;
  p.inputs = check.names(root, "inputs", 1, "u");
  within_limit(check, "sections.disturbance", p.b_w.cols, kMaxDisturbances, "disturbance inputs", "kMaxDisturbances");
}

/// Whether the root holds what only a continuous plant takes: cost.Q1c or Q2c, a board, a table.
bool wants_continuous(const json& root) {
  if (root.contains("board") || root.contains("table")) return true;
  const auto cost = root.find("cost");
  return cost != root.end() && cost->is_object() && (cost->contains("Q1c") || cost->contains("Q2c"));
}

/// The discrete plant `p` (matrices and per-step noise read) replaced by its exact continuous
/// equivalent (zoh_inverse); refusals name Phi, Gamma, B_w or noise.process_covariance_per_period.
void to_continuous_equivalent(PlantDescription& p, const Checker& check) {
  const std::string why = " (a discrete plant with cost.Q1c/Q2c, a board or a table is read as its continuous equivalent)";
  if (p.q() != 0) check.fail("B_w", "a per-step disturbance input has no continuous equivalent here" + why);
  ZohInverse r;
  try {
    r = zoh_inverse(p.phi, p.gamma, static_cast<double>(p.period_us) * 1e-6, p.process_covariance_per_period);
  } catch (const ZohInverseError& e) {
    const char* field = e.part() == ZohInverseError::Part::kPhi     ? "Phi"
                        : e.part() == ZohInverseError::Part::kGamma ? "Gamma"
                                                                    : "noise.process_covariance_per_period";
    check.fail(field, e.what() + why);
  } catch (const std::exception& e) {
    check.fail("Phi", e.what() + why);
  }
  p.form = PlantForm::kContinuous;
  p.from_discrete = true;
  p.d2c_relative_error = r.relative_error;
  p.d2c_noise_relative_error = r.noise_relative_error;
  p.d2c_phi_condition = r.phi_condition;
  p.d2c_phi = std::move(p.phi);
  p.d2c_gamma = std::move(p.gamma);
  p.phi = {};
  p.gamma = {};
  p.a = std::move(r.a);
  p.b = std::move(r.b);
  p.process_intensity = std::move(r.qc);
  p.process_covariance_per_period = {};
}

}  // namespace

const char* to_string(PlantForm f) {
  switch (f) {
    case PlantForm::kContinuous: return "continuous";
    case PlantForm::kDiscrete: return "discrete";
    case PlantForm::kSections: return "sections";
  }
  return "?";
}

PlantDescription parse_plant(const std::string& json_text, const std::string& source) {
  const Checker check(source);
  const json root = detail::parse_strict(json_text, source);
  if (!root.is_object()) throw PlantError(source + ": the plant description must be a JSON object");
  check.only_keys(root, "", {"name", "description", "form", "states", "inputs", "outputs", "disturbances", "A", "B",
                             "Phi", "Gamma", "C", "B_w", "sections", "period_us", "cost", "noise", "tracked_outputs",
                             "table", "board", "actuator"});
  PlantDescription p;
  p.source = source;
  p.name = check.optional_string(root, "name", "");
  if (p.name.empty()) p.name = "plant";
  p.description = check.optional_string(root, "description", "");
  const std::string form = check.optional_string(root, "form", "");
  if (form.empty() || form == "continuous") {
    p.form = PlantForm::kContinuous;
  } else if (form == "discrete") {
    p.form = PlantForm::kDiscrete;
  } else if (form == "sections") {
    p.form = PlantForm::kSections;
  } else {
    check.fail("form", "must be \"continuous\", \"discrete\" or \"sections\", got \"" + form + "\"");
  }
  if (p.form != PlantForm::kSections && root.contains("sections")) check.fail("sections", "needs \"form\": \"sections\"");
  // The period first: the sections are realized at it, the table and board are checked against it.
  p.period_us = static_cast<std::int32_t>(check.integer(root, "period_us", "", 1, 60'000'000));
  if (p.form == PlantForm::kSections) {
    parse_sections(root, p, check);
  } else {
    parse_matrices(root, p, check);
    p.states = check.names(root, "states", p.n(), "x");
  }
  p.outputs = check.names(root, "outputs", p.p(), "y");
  p.disturbances = check.names(root, "disturbances", p.q(), "w");

  // A discrete plant with what only a continuous one takes: its exact continuous equivalent,
  // from the per-step noise (read as the discrete form reads it) on.
  const bool equivalent = p.form == PlantForm::kDiscrete && wants_continuous(root);
  if (equivalent) {
    detail::parse_noise(root, p, check);
    to_continuous_equivalent(p, check);
  }
  detail::parse_cost(root, p, check);
  if (!equivalent) detail::parse_noise(root, p, check);
  detail::parse_tracked_outputs(root, p, check);
  detail::parse_table(root, p, check);
  detail::parse_board_or_actuator(root, p, check);
  return p;
}

PlantDescription load_plant_file(const std::string& path) { return parse_plant(detail::read_plant_text(path), path); }

PlantDescription reference_plant() { return parse_plant(reference_plant_json(), "built-in reference board"); }

void require_continuous_board_and_table(const PlantDescription& plant, const std::string& user) {
  std::string missing;
  if (!plant.continuous()) missing = "a continuous plant (this one is " + std::string(to_string(plant.form)) + ")";
  else if (!plant.has_table) missing = "a 'table' section";
  else if (!plant.has_board) missing = "a PWM 'board' section";
  else if (plant.cost_form == CostForm::kNone) missing = "a 'cost' section (an LQR gain)";
  if (!missing.empty()) throw PlantError(plant.source + ": " + user + " needs " + missing);
}

}  // namespace oneshot::design
