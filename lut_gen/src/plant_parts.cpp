/// @file plant_parts.cpp
/// @brief Cost, noise, tracked outputs, table, board and actuator of a plant file.
#include "plant_parts.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "oneshot/design/dense_ops.hpp"

namespace oneshot::design::detail {
namespace {

using nlohmann::json;

/// Largest |voltage| a board's PWM levels and ADC range may have (V): the boards this
/// design step targets run on a few volts; ±1 kV leaves room for power stages while every
/// product of the design (gains × ranges, costs) stays far from overflow.
constexpr double kMaxBoardVolts = 1000.0;

std::string num(double v) {
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

/// The n×n (or q×q) matrix at noise.<key>, when present, checked as a covariance.
DenseMatrix optional_covariance(const json& obj, const char* key, std::size_t size, const std::string& what,
                                const Checker& check) {
  if (!obj.contains(key)) return {};
  const std::string field = std::string("noise.") + key;
  DenseMatrix m = check.matrix(obj, key, "noise.");
  check.shape(m, field, size, size, what);
  check.covariance(m, field, false);
  return m;
}

}  // namespace

void parse_cost(const json& root, PlantDescription& p, const Checker& check) {
  if (!root.contains("cost")) return;
  const json& cost = check.object(root, "cost", "");
  check.only_keys(cost, "cost.", {"Q1c", "Q2c", "Q1", "Qy", "Q2"});
  const std::size_t n = p.n();
  const std::size_t m = p.m();
  const bool continuous = cost.contains("Q1c") || cost.contains("Q2c");
  if (continuous) {
    if (!p.continuous()) check.fail("cost.Q1c", "a continuous cost needs a continuous plant: give cost.Q1 or cost.Qy, and cost.Q2");
    for (const char* k : {"Q1", "Qy", "Q2"})
      if (cost.contains(k)) check.fail(std::string("cost.") + k, "cannot be mixed with the continuous Q1c, Q2c");
    p.cost_form = CostForm::kContinuous;
    p.q1c = check.matrix(cost, "Q1c", "cost.");
    check.shape(p.q1c, "cost.Q1c", n, n, "one row and column per state");
    check.covariance(p.q1c, "cost.Q1c", false);
    p.q2c = check.matrix(cost, "Q2c", "cost.");
    check.shape(p.q2c, "cost.Q2c", m, m, "one row and column per input");
    check.covariance(p.q2c, "cost.Q2c", true);
    return;
  }
  p.cost_form = CostForm::kDiscrete;
  if (cost.contains("Q1") == cost.contains("Qy")) check.fail("cost.Q1", "give exactly one of cost.Q1 and cost.Qy");
  if (cost.contains("Q1")) {
    p.q1 = check.matrix(cost, "Q1", "cost.");
    check.shape(p.q1, "cost.Q1", n, n, "one row and column per state");
    check.covariance(p.q1, "cost.Q1", false);
  } else {
    const DenseMatrix qy = check.matrix(cost, "Qy", "cost.");
    check.shape(qy, "cost.Qy", p.p(), p.p(), "one row and column per output");
    check.covariance(qy, "cost.Qy", false);
    p.q1 = transpose(p.c) * qy * p.c;  // Q1 = Cᵀ Qy C
    symmetrize(p.q1);
    for (double& v : p.q1.values) v = v + 0.0;  // −0 → +0
  }
  p.q2 = check.matrix(cost, "Q2", "cost.");
  check.shape(p.q2, "cost.Q2", m, m, "one row and column per input");
  check.covariance(p.q2, "cost.Q2", true);
}

void parse_noise(const json& root, PlantDescription& p, const Checker& check) {
  const json& noise = check.object(root, "noise", "");
  if (noise.contains("process_covariance")) {
    check.fail("noise.process_covariance",
               "ambiguous and no longer read: give noise.process_covariance_per_period (the covariance added per "
               "period h, the former meaning; Q_c = Qn/h) or noise.process_intensity (the continuous intensity Q_c)");
  }
  check.only_keys(noise, "noise.",
                  {"process_intensity", "process_covariance_per_period", "disturbance_intensity",
                   "disturbance_covariance_per_period", "measurement_covariance", "initial_covariance"});
  const std::size_t n = p.n();
  const std::size_t q = p.q();
  if (!p.continuous()) {
    for (const char* k : {"process_intensity", "disturbance_intensity"})
      if (noise.contains(k)) {
        check.fail(std::string("noise.") + k,
                   "a continuous intensity needs a continuous plant: give the per-step covariance (*_covariance_per_period)");
      }
  }
  if (noise.contains("process_intensity") && noise.contains("process_covariance_per_period")) {
    check.fail("noise.process_intensity", "give either process_intensity (Q_c) or process_covariance_per_period, not both");
  }
  p.process_intensity = optional_covariance(noise, "process_intensity", n, "one row and column per state", check);
  p.process_covariance_per_period =
      optional_covariance(noise, "process_covariance_per_period", n, "one row and column per state", check);

  const bool dist_noise = noise.contains("disturbance_intensity") || noise.contains("disturbance_covariance_per_period");
  if (q == 0 && dist_noise) {
    check.fail(noise.contains("disturbance_intensity") ? "noise.disturbance_intensity" : "noise.disturbance_covariance_per_period",
               "needs a disturbance input B_w");
  }
  if (q > 0) {
    if (noise.contains("disturbance_intensity") == noise.contains("disturbance_covariance_per_period")) {
      check.fail("noise.disturbance_covariance_per_period",
                 "give exactly one of disturbance_intensity and disturbance_covariance_per_period for B_w");
    }
    p.disturbance_intensity = optional_covariance(noise, "disturbance_intensity", q, "one row and column per disturbance", check);
    p.disturbance_covariance_per_period =
        optional_covariance(noise, "disturbance_covariance_per_period", q, "one row and column per disturbance", check);
  }
  if (p.process_intensity.rows == 0 && p.process_covariance_per_period.rows == 0 && q == 0) {
    check.fail("noise.process_covariance_per_period",
               "is missing (give it, or noise.process_intensity for a continuous plant, or a disturbance B_w with its covariance)");
  }
  p.measurement_covariance = check.matrix(noise, "measurement_covariance", "noise.");
  check.shape(p.measurement_covariance, "noise.measurement_covariance", p.p(), p.p(), "one row and column per output");
  check.covariance(p.measurement_covariance, "noise.measurement_covariance", true);
  if (noise.contains("initial_covariance")) {
    p.has_initial_covariance = true;
    p.initial_covariance = check.matrix(noise, "initial_covariance", "noise.");
    check.shape(p.initial_covariance, "noise.initial_covariance", n, n, "one row and column per state");
    check.covariance(p.initial_covariance, "noise.initial_covariance", true);
  }
}

void parse_tracked_outputs(const json& root, PlantDescription& p, const Checker& check) {
  if (!root.contains("tracked_outputs")) {
    if (p.p() == p.m()) {
      for (std::size_t i = 0; i < p.p(); ++i) p.tracked_outputs.push_back(i);
    }
    return;
  }
  p.tracked_outputs_declared = true;
  const json& t = root["tracked_outputs"];
  if (!t.is_array()) check.fail("tracked_outputs", "must be an array of output names");
  if (t.size() != p.m()) {
    check.fail("tracked_outputs", "must name " + std::to_string(p.m()) + " output(s), one per input, has " +
                                      std::to_string(t.size()));
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    const std::string field = "tracked_outputs[" + std::to_string(i) + "]";
    if (!t[i].is_string()) check.fail(field, "must be an output name");
    const auto it = std::find(p.outputs.begin(), p.outputs.end(), t[i].get<std::string>());
    if (it == p.outputs.end()) check.fail(field, "'" + t[i].get<std::string>() + "' is not one of the outputs");
    const auto index = static_cast<std::size_t>(it - p.outputs.begin());
    if (std::find(p.tracked_outputs.begin(), p.tracked_outputs.end(), index) != p.tracked_outputs.end()) {
      check.fail(field, "names an output twice");
    }
    p.tracked_outputs.push_back(index);
  }
}

void parse_table(const json& root, PlantDescription& p, const Checker& check) {
  if (!root.contains("table")) return;
  if (!p.continuous()) check.fail("table", "a Phi(tau) table needs a continuous plant (A, B)");
  const json& table = check.object(root, "table", "");
  check.only_keys(table, "table.", {"granularity_us", "range_us", "max_bytes"});
  p.has_table = true;
  p.table_granularity_us = static_cast<std::int32_t>(check.integer(table, "granularity_us", "table.", 1, 10'000'000));
  p.table_range_us = static_cast<std::int32_t>(check.integer(table, "range_us", "table.", 1, 60'000'000));
  const std::string g = std::to_string(p.table_granularity_us);
  if (p.period_us % p.table_granularity_us != 0) {
    check.fail("table.granularity_us", "the period h = " + std::to_string(p.period_us) +
                                           " us is not a multiple of the granularity " + g + " us");
  }
  if (p.table_range_us % p.table_granularity_us != 0) {
    check.fail("table.range_us", "must be a multiple of table.granularity_us (" + g + ")");
  }
  if (p.table_range_us < p.period_us) {
    check.fail("table.range_us", std::to_string(p.table_range_us) + " us is below the period h = " +
                                     std::to_string(p.period_us) + " us: most tau in [0, h] would be clamped");
  }
  if (p.table_range_us / p.table_granularity_us > 4096) {
    check.fail("table.range_us", "more than 4096 grid steps of table.granularity_us");
  }
  p.table_max_bytes = static_cast<std::int32_t>(check.integer(table, "max_bytes", "table.", 1, 1 << 20));
}

void parse_board_or_actuator(const json& root, PlantDescription& p, const Checker& check) {
  const std::size_t m = p.m();
  if (root.contains("board") && root.contains("actuator")) {
    check.fail("actuator", "give either a PWM board or an actuator range, not both (the board's PWM levels are the range)");
  }
  if (root.contains("actuator")) {
    const json& act = check.object(root, "actuator", "");
    check.only_keys(act, "actuator.", {"u_min", "u_max"});
    p.has_actuator_range = true;
    p.u_min = check.vector_of(act, "u_min", "actuator.", m);
    p.u_max = check.vector_of(act, "u_max", "actuator.", m);
    for (std::size_t j = 0; j < m; ++j)
      if (!(p.u_min[j] < p.u_max[j])) check.fail("actuator.u_max[" + std::to_string(j) + "]", "must be above actuator.u_min");
    return;
  }
  if (!root.contains("board")) return;
  if (!p.continuous()) check.fail("board", "a PWM board needs a continuous plant (the circuit runs between PWM edges)");
  const json& board = check.object(root, "board", "");
  check.only_keys(board, "board.", {"pwm_frequency_hz", "pwm_duty_steps", "pwm_low_volts", "pwm_high_volts",
                                    "adc_bits", "adc_min_volts", "adc_max_volts"});
  p.has_board = true;
  BoardDescription& bd = p.board;
  bd.pwm_frequency_hz = check.number_in(board, "pwm_frequency_hz", "board.", 0, 1e7);
  bd.pwm_duty_steps = static_cast<std::int32_t>(check.integer(board, "pwm_duty_steps", "board.", 1, 1 << 20));
  const double h_s = static_cast<double>(p.period_us) * 1e-6;
  // A PWM period longer than h cannot realize a duty within one control period (and the
  // harness's integer-ns PWM clock would overflow for f → 0).
  if (!(bd.pwm_frequency_hz * h_s >= 1.0)) {
    check.fail("board.pwm_frequency_hz", "the PWM period 1/f = " + num(1e6 / bd.pwm_frequency_hz) +
                                             " us is longer than the control period h = " +
                                             std::to_string(p.period_us) + " us (need f >= 1/h = " +
                                             num(1.0 / h_s) + " Hz)");
  }
  const double step_ns = 1e9 / (bd.pwm_frequency_hz * bd.pwm_duty_steps);
  if (!(step_ns >= 1.0)) {
    check.fail("board.pwm_duty_steps", std::to_string(bd.pwm_duty_steps) + " duty steps at " +
                                           num(bd.pwm_frequency_hz) + " Hz give a duty step of " + num(step_ns) +
                                           " ns, below the 1 ns resolution of the emulated PWM");
  }
  // Each voltage within ±kMaxBoardVolts, the field named (a ±1e308 V range would only show
  // later as a diverged run).
  const auto volts = [&](const char* key, std::size_t count) {
    std::vector<double> v = check.vector_of(board, key, "board.", count);
    for (std::size_t j = 0; j < v.size(); ++j)
      if (!(v[j] >= -kMaxBoardVolts && v[j] <= kMaxBoardVolts)) {
        check.fail("board." + std::string(key) + "[" + std::to_string(j) + "]",
                   num(v[j]) + " V is outside the supported board range of +-" + num(kMaxBoardVolts) + " V");
      }
    return v;
  };
  bd.pwm_low_volts = volts("pwm_low_volts", m);
  bd.pwm_high_volts = volts("pwm_high_volts", m);
  for (std::size_t j = 0; j < m; ++j)
    if (!(bd.pwm_low_volts[j] < bd.pwm_high_volts[j])) {
      check.fail("board.pwm_high_volts[" + std::to_string(j) + "]", "must be above board.pwm_low_volts");
    }
  bd.adc_bits = static_cast<int>(check.integer(board, "adc_bits", "board.", 1, 24));
  bd.adc_min_volts = volts("adc_min_volts", p.p());
  bd.adc_max_volts = volts("adc_max_volts", p.p());
  for (std::size_t j = 0; j < p.p(); ++j)
    if (!(bd.adc_min_volts[j] < bd.adc_max_volts[j])) {
      check.fail("board.adc_max_volts[" + std::to_string(j) + "]", "must be above board.adc_min_volts");
    }
  p.u_min = bd.pwm_low_volts;
  p.u_max = bd.pwm_high_volts;
}

}  // namespace oneshot::design::detail
