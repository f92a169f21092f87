/// @file controller_synthesis.cpp
/// @brief The design step (see controller_synthesis.hpp for the equations).
#include "oneshot/design/controller_synthesis.hpp"

#include <cmath>
#include <cstdio>

#include "oneshot/design/dare.hpp"
#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/sampled_model.hpp"
#include "oneshot/design/spectrum.hpp"
#include "synthesis_parts.hpp"

namespace oneshot::design {
namespace detail {

std::string significant(double v, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace detail
namespace {

std::string sci(double v) { return detail::significant(v, 6); }

/// LQR on the plant states (all states, or the leading n − exogenous ones), then the
/// input-disturbance cancellation L_d = C_d for an exogenous model.
void design_lqr(const PlantDescription& plant, DesignResult& d) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  d.l = DenseMatrix::zeros(m, n);
  if (plant.cost_form == CostForm::kNone) {
    d.lqr_unavailable_reason = "the plant file has no cost";
    return;
  }
  const std::size_t np = n - plant.exogenous_states;
  const DenseMatrix phi = block(d.phi_h, 0, 0, np, np);
  const DenseMatrix gamma = block(d.gamma_h, 0, 0, np, m);
  if (plant.exogenous_states != 0) {
    // Exogenous block: Φ = [[Φ_p, Φ_pd], [0, A_d]], Γ = [Γ_p; 0]; matched iff Φ_pd = Γ_p C_d.
    const DenseMatrix c_d = block(plant.c_bar, 0, np, m, n - np);
    const DenseMatrix mismatch = block(d.phi_h, 0, np, np, n - np) - gamma * c_d;
    if (max_abs(mismatch) > 1e-12 * std::max(1.0, max_abs(d.phi_h))) {
      throw DesignError("design: LQR: the exogenous disturbance does not enter at the input (Phi_pd != Gamma_p C_d)");
    }
    const DenseMatrix q1_d = block(d.q1, 0, np, n, n - np);
    if (max_abs(q1_d) != 0) {
      throw DesignError("design: LQR: the cost weights the exogenous disturbance states, which no input can "
                        "regulate; weight the plant states only (e.g. cost.Qy)");
    }
    d.exogenous_states = plant.exogenous_states;
    d.exogenous_radius = spectral_radius(block(d.phi_h, np, np, n - np, n - np));
  }
  const ModeCheck stab = stabilizable(phi, gamma);
  if (!stab.ok) {
    throw DesignError("design: LQR: (Phi, Gamma) is not stabilizable: the modes " + stab.describe() +
                      " are not controllable from the input");
  }
  const DenseMatrix q1 = block(d.q1, 0, 0, np, np);
  const DenseMatrix q12 = block(d.q12, 0, 0, np, m);
  const DareSolution sol = solve_dare(phi, gamma, q1, d.q2, q12);
  d.lqr_residual = sol.residual;
  if (sol.status != DareStatus::kOk) {
    throw DesignError(std::string("design: LQR Riccati equation failed: ") + to_string(sol.status) +
                      " (relative residual " + sci(sol.residual) + ", nearest pencil eigenvalue at ||l| - 1| = " +
                      sci(sol.unit_circle_distance) + "): a marginal mode the cost does not weight?");
  }
  const DenseMatrix s = sol.x;
  const DenseMatrix gt = transpose(gamma);
  const SolveResult gain = solve(d.q2 + gt * s * gamma, gt * s * phi + transpose(q12));
  if (!gain.ok) throw DesignError("design: LQR gain equation is singular");
  d.riccati = s;
  set_block(d.l, 0, 0, gain.x);
  if (plant.exogenous_states != 0) set_block(d.l, 0, np, block(plant.c_bar, 0, np, m, n - np));
  d.closed_loop_radius = spectral_radius(phi - gamma * gain.x);
  if (!(d.closed_loop_radius < 1.0)) {
    throw DesignError("design: the LQR closed loop is not stable (spectral radius " + sci(d.closed_loop_radius) + ")");
  }
  d.lqr_available = true;
}

/// Steady-state Kalman filter for one period with Q_d(h).
void design_kalman(const PlantDescription& plant, DesignResult& d) {
  const std::size_t n = plant.n();
  const ModeCheck det = detectable(d.phi_h, plant.c);
  if (!det.ok) {
    throw DesignError("design: Kalman filter: (Phi, C) is not detectable: the modes " + det.describe() +
                      " (|l| >= 1) are invisible in the outputs, so no stable estimator exists");
  }
  const DareSolution sol = solve_dare(transpose(d.phi_h), transpose(plant.c), d.qd_h, plant.measurement_covariance);
  d.kalman_residual = sol.residual;
  if (sol.status != DareStatus::kOk) {
    throw DesignError(std::string("design: Kalman Riccati equation failed: ") + to_string(sol.status) +
                      " (relative residual " + sci(sol.residual) + ", nearest pencil eigenvalue at ||l| - 1| = " +
                      sci(sol.unit_circle_distance) + "): a marginal mode the process noise does not excite?");
  }
  DenseMatrix prior = sol.x;
  symmetrize(prior);
  const SolveResult kt = solve(plant.c * prior * transpose(plant.c) + plant.measurement_covariance, plant.c * prior);
  if (!kt.ok) throw DesignError("design: Kalman filter: the innovation covariance is singular");
  const DenseMatrix k = transpose(kt.x);
  DenseMatrix posterior = (identity(n) - k * plant.c) * prior;
  symmetrize(posterior);
  d.kalman_prior = prior;
  d.kalman_posterior = posterior;
  d.kalman_gain = k;
  d.estimator_radius = spectral_radius((identity(n) - k * plant.c) * d.phi_h);
  if (!(d.estimator_radius < 1.0)) {
    throw DesignError("design: Kalman filter: the steady-state estimator (I - K C) Phi is not stable (spectral radius " +
                      sci(d.estimator_radius) + ")");
  }
}

/// Actuator and sensor models from the board, or the actuator range alone.
void converters(const PlantDescription& plant, DesignResult& d) {
  d.u_min = plant.u_min;
  d.u_max = plant.u_max;
  if (!plant.has_board) return;
  const BoardDescription& bd = plant.board;
  for (std::size_t j = 0; j < plant.m(); ++j) {
    const double span = bd.pwm_high_volts[j] - bd.pwm_low_volts[j];
    d.volts_per_step.push_back(span / bd.pwm_duty_steps);
    d.steps_per_volt.push_back(bd.pwm_duty_steps / span);
  }
  d.actuator_steps = bd.pwm_duty_steps;
  for (std::size_t o = 0; o < plant.p(); ++o) {
    const double lsb = (bd.adc_max_volts[o] - bd.adc_min_volts[o]) / std::ldexp(1.0, bd.adc_bits);
    d.volts_per_code.push_back(lsb);
    d.y_offset.push_back(bd.adc_min_volts[o] + 0.5 * lsb);
  }
}

}  // namespace

DesignResult synthesize(const PlantDescription& plant) {
  DesignResult d;
  d.period_s = static_cast<double>(plant.period_us) * 1e-6;
  try {
    const SampledModel s = sample_plant(plant);
    d.phi_h = s.phi;
    d.gamma_h = s.gamma;
    d.gamma_w_h = s.gamma_w;
    d.qd_h = s.qd;
    d.qc = s.qc;
    d.q_constant = s.q_constant;
    const SampledCost c = sample_cost(plant);
    d.q1 = c.q1;
    d.q12 = c.q12;
    d.q2 = c.q2;
  } catch (const std::domain_error& e) {
    throw DesignError(e.what());
  }
  design_lqr(plant, d);
  design_kalman(plant, d);
  detail::design_feedforward(plant, d);
  detail::design_deadbeat(plant, d);
  d.p0 = plant.has_initial_covariance ? plant.initial_covariance : d.kalman_prior;
  d.r = plant.measurement_covariance;
  converters(plant, d);
  return d;
}

}  // namespace oneshot::design
