/// @file fixed_formats.cpp
/// @brief Fixed-point format choice (see fixed_formats.hpp).
#include "oneshot/design/fixed_formats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"

namespace oneshot::design {

double QFormat::max_value() const { return std::ldexp(std::ldexp(1.0, bits - 1) - 1, -frac); }
double QFormat::resolution() const { return std::ldexp(1.0, -frac); }

std::string QFormat::cpp_type() const {
  return "::oneshot::Fixed<std::int" + std::to_string(bits) + "_t, " + std::to_string(frac) + ">";
}

long long QFormat::raw_of(double v, const std::string& what) const {
  const double scaled = std::ldexp(v, frac);
  const double top = std::ldexp(1.0, bits - 1);
  const double r = std::round(scaled);
  if (!(r < top && r >= -top)) {
    std::ostringstream o;
    o << "fixed point: " << what << " = " << v << " does not fit its format " << cpp_type() << " (max "
      << max_value() << ")";
    throw DesignError(o.str());
  }
  return static_cast<long long>(r);
}

namespace {

/// The format of `bits` storage with the most fractional bits holding |v| ≤ range.
QFormat fit(int bits, double range) {
  QFormat f;
  f.bits = bits;
  // Largest frac with range · 2^frac ≤ 2^(bits−1) − 1.
  int e = 0;
  std::frexp(range, &e);  // range < 2^e
  f.frac = bits - 1 - e;
  while (range > f.max_value()) --f.frac;
  return f;
}

double max_abs(const DenseMatrix& m) {
  double r = 0;
  for (double v : m.values) r = std::max(r, std::fabs(v));
  return r;
}

struct Spans {
  double phi = 0, gamma = 0, qd = 0;
};

template <std::size_t N, std::size_t M>
Spans spans(const PlantDescription& plant, const DesignResult& d, std::int32_t t_max_us) {
  const GenericDiscretizer<UniformFormat<double>, N, M> gen(continuous_model_per_us<double, N, M>(plant, d));
  Spans s;
  const std::int32_t step = std::max<std::int32_t>(1, t_max_us / 400);
  for (std::int32_t t = 0; t <= t_max_us; t += step) {
    Discretization<UniformFormat<double>, N, M> dd;
    if (gen.discretize(t, dd, WithQd::kYes) != Status::kOk) {
      throw DesignError("fixed point: the exponential of A·t fails at t = " + std::to_string(t) + " us");
    }
    for (std::size_t k = 0; k < N * N; ++k) {
      s.phi = std::max(s.phi, std::fabs(dd.phi[k]));
      s.qd = std::max(s.qd, std::fabs(dd.qd[k]));
    }
    for (std::size_t k = 0; k < N * M; ++k) s.gamma = std::max(s.gamma, std::fabs(dd.gamma[k]));
  }
  return s;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw DesignError("fixed point: " + what);
}

}  // namespace

std::int32_t fixed_time_span_us(const PlantDescription& plant) {
  return 2 * std::max(plant.period_us, plant.table_range_us);
}

FixedFormats choose_fixed_formats(const PlantDescription& plant, const DesignResult& d) {
  FixedFormats f;
  const auto record = [&](const std::string& name, QFormat& slot, int bits, double range, const std::string& why) {
    slot = fit(bits, range);
    f.table.push_back({name, slot, range, why});
  };
  std::ostringstream o;
  const auto fmt = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };

  // Converters.
  double adc = 0;
  double lsb = 1e300;
  for (std::size_t k = 0; k < plant.p(); ++k) {
    adc = std::max({adc, std::fabs(plant.board.adc_min_volts[k]), std::fabs(plant.board.adc_max_volts[k])});
    lsb = std::min(lsb, d.volts_per_code[k]);
  }
  record("state", f.state, 32, 2 * adc, "2x the ADC range +-" + fmt(adc) + " V");
  require(f.state.resolution() <= lsb / 4,
          "state: the ADC range +-" + fmt(adc) + " V with a " + fmt(lsb) + " V LSB needs finer than a 32-bit format");
  double pwm = 0;
  double step = 1e300;
  double steps_per_volt = 0;
  for (std::size_t j = 0; j < plant.m(); ++j) {
    pwm = std::max({pwm, std::fabs(plant.board.pwm_low_volts[j]), std::fabs(plant.board.pwm_high_volts[j])});
    step = std::min(step, d.volts_per_step[j]);
    steps_per_volt = std::max(steps_per_volt, d.steps_per_volt[j]);
  }
  record("input", f.input, 32, 2 * pwm, "2x the PWM levels +-" + fmt(pwm) + " V");
  require(f.input.resolution() <= step / 2,
          "input: the PWM step " + fmt(step) + " V is finer than a 32-bit input format can resolve");
  record("code_step", f.code_step, 32, 2 * std::max(step, lsb), "volts per ADC code / PWM step");
  record("actuator_steps", f.actuator_steps, 32, 2.0 * plant.board.pwm_duty_steps, "2x the PWM duty steps");
  record("inverse_input", f.inverse_input, 32, 2 * steps_per_volt, "PWM steps per volt");

  // Φ, Γ, Q_d over the span the filters use.
  const std::int32_t span = fixed_time_span_us(plant);
  const Spans s = with_dimensions(plant.n(), plant.m(), 1, [&](auto n, auto m, auto) {
    return spans<decltype(n)::value, decltype(m)::value>(plant, d, span);
  });
  record("transition", f.transition, 16, 1.25 * s.phi, "1.25x max|Phi(t)| over 0-" + fmt(span * 1e-3) + " ms");
  require(f.transition.frac >= 11, "transition: Phi(t) reaches " + fmt(s.phi) + " over 0-" + fmt(span * 1e-3) +
                                       " ms, too large for a 16-bit format with 11 fractional bits (|Phi| < 16)");
  record("input_gain", f.input_gain, 16, 1.25 * s.gamma, "1.25x max|Gamma(t)| over 0-" + fmt(span * 1e-3) + " ms");
  require(f.input_gain.frac >= 11, "input_gain: Gamma(t) reaches " + fmt(s.gamma) + ", too large for a 16-bit format");
  record("compute", f.compute, 32, 2 * std::max({s.phi, s.gamma, 1.0}), "generic routine: 2x max(|Phi|, |Gamma|, 1)");
  require(f.compute.frac >= 20, "compute: the generic routine's entries reach " + fmt(std::max(s.phi, s.gamma)) +
                                    ", too large for a 32-bit format with 20 fractional bits");

  // Covariances.
  const double cov = std::max({max_abs(d.p0), max_abs(d.kalman_prior), max_abs(d.r), max_abs(d.q_constant), s.qd});
  record("covariance", f.covariance, 32, 256 * cov, "256x max(P0, P, R, Q, Qd) = 256x " + fmt(cov));
  double smallest = 1e300;
  for (std::size_t i = 0; i < plant.n(); ++i) smallest = std::min(smallest, d.kalman_posterior(i, i));
  require(f.covariance.resolution() <= 1e-4 * smallest,
          "covariance: entries span " + fmt(smallest) + " to " + fmt(256 * cov) +
              ", more than a 32-bit format resolves to 1e-4 of the smallest steady-state variance");
  double r_min = 1e300;
  for (std::size_t k = 0; k < plant.p(); ++k) r_min = std::min(r_min, d.r(k, k));
  record("inverse_covariance", f.inverse_covariance, 32, 2 / r_min, "2/min(R)");
  require(f.covariance.frac + f.inverse_covariance.frac <= 62 && f.covariance.frac + f.inverse_covariance.frac >= 0,
          "inverse_covariance: 1/S and S cannot share a 64-bit reciprocal");

  // Gains.
  record("kalman_gain", f.kalman_gain, 16, 2 * std::max(1.0, max_abs(d.kalman_gain)), "2x max(|K|, 1)");
  const double gains = std::max({max_abs(d.l), max_abs(d.nx), max_abs(d.nu), max_abs(d.deadbeat_gain)});
  record("feedback_gain", f.feedback_gain, 16, 2 * gains, "2x max(|L|, |Nx|, |Nu|, |Kdb|)");
  require(f.feedback_gain.frac >= 8, "feedback_gain: gains reach " + fmt(gains) + ", too large for a 16-bit format");
  f.fraction = QFormat{16, 15};
  f.table.push_back({"fraction", f.fraction, f.fraction.max_value(), "sub-grid residual r in [0, 1)"});

  // Generic routine per-µs model, with Q_c scaled so that Q_c·t·2^k stays below 1/2.
  const double a_us = max_abs(plant.a) * 1e-6;
  const double b_us = max_abs(plant.b) * 1e-6;
  const double qc_us = max_abs(d.qc) * 1e-6;
  // A zero matrix fits any format: give it an ordinary one.
  record("model_a", f.model_a, 32, a_us > 0 ? 1.01 * a_us : 1.0, "max|A| per us");
  record("model_b", f.model_b, 32, b_us > 0 ? 1.01 * b_us : 1.0, "max|B| per us");
  const double qd_span = qc_us * span;
  f.qd_scale_shift = qd_span > 0 ? static_cast<int>(std::floor(std::log2(0.5 / qd_span))) : 0;
  f.qd_scale_shift = std::clamp(f.qd_scale_shift, 0, 40);
  record("model_qc", f.model_qc, 32, qc_us > 0 ? 1.01 * std::ldexp(qc_us, f.qd_scale_shift) : 1.0,
         "max|Qc| per us x 2^" + std::to_string(f.qd_scale_shift));
  require(f.model_a.frac < 63 && f.model_b.frac < 63 && f.model_qc.frac < 63,
          "model: A, B or Q_c per us is too small for a 32-bit format (below 2^-32)");
  require(f.compute.frac + f.qd_scale_shift < 63, "model_qc: the scaled Q_d does not fit the compute format");
  return f;
}

}  // namespace oneshot::design
