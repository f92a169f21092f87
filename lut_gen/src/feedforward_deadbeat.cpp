/// @file feedforward_deadbeat.cpp
/// @brief Set-point feed-forward and the current deadbeat observer of the design step.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"
#include "synthesis_parts.hpp"

namespace oneshot::design::detail {
namespace {

std::string sci(double v) { return significant(v, 3); }

}  // namespace

void design_feedforward(const PlantDescription& plant, DesignResult& d) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  const std::size_t p = plant.p();
  d.nx = DenseMatrix::zeros(n, p);
  d.nu = DenseMatrix::zeros(m, p);
  d.tracked_outputs = plant.tracked_outputs;
  if (plant.tracked_outputs.size() != m) {
    d.tracking_unavailable_reason = "the plant has " + std::to_string(p) + " outputs and " + std::to_string(m) +
                                    " inputs: declare tracked_outputs (" + std::to_string(m) + " output names)";
    return;
  }
  // Equilibrium: [[A, B], [C_t, 0]] [N_x; N_u] = [0; I] (continuous), with Φ − I for discrete plants.
  DenseMatrix sys = DenseMatrix::zeros(n + m, n + m);
  set_block(sys, 0, 0, plant.continuous() ? plant.a : d.phi_h - identity(n));
  set_block(sys, 0, n, plant.continuous() ? plant.b : d.gamma_h);
  set_block(sys, n, 0, select_rows(plant.c, plant.tracked_outputs));
  DenseMatrix rhs = DenseMatrix::zeros(n + m, m);
  for (std::size_t i = 0; i < m; ++i) rhs(n + i, i) = 1.0;
  const SolveResult sol = solve(sys, rhs, 1e-12);
  if (!sol.ok) {
    d.tracking_unavailable_reason = "no unique equilibrium for the tracked outputs: [[A, B], [C_t, 0]] is singular "
                                    "(reciprocal condition " + sci(sol.rcond) + ")";
    return;
  }
  DenseMatrix nx = block(sol.x, 0, 0, n, m);
  DenseMatrix nu = block(sol.x, n, 0, m, m);
  flush_tiny(nx, 1e-14);  // exact zeros, not rounding dust
  flush_tiny(nu, 1e-14);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t out = plant.tracked_outputs[j];
    for (std::size_t i = 0; i < n; ++i) d.nx(i, out) = nx(i, j);
    for (std::size_t i = 0; i < m; ++i) d.nu(i, out) = nu(i, j);
  }
  d.tracking = true;
}

void design_deadbeat(const PlantDescription& plant, DesignResult& d) {
  const std::size_t n = plant.n();
  d.deadbeat_gain = DenseMatrix::zeros(n, plant.p());
  if (plant.p() != 1) {
    d.deadbeat_unavailable_reason = "only single-output plants have the current deadbeat observer (p = " +
                                    std::to_string(plant.p()) + ")";
    return;
  }
  const ModeCheck obs = observable(d.phi_h, plant.c);
  if (!obs.ok) {
    d.deadbeat_unavailable_reason = "(Phi, C) is not observable: unobservable modes " + obs.describe();
    return;
  }
  // O = [CΦ; CΦ²; …; CΦⁿ]; K_db = Φⁿ O⁻¹ e_n.
  DenseMatrix o = DenseMatrix::zeros(n, n);
  DenseMatrix power = d.phi_h;
  for (std::size_t i = 0; i < n; ++i) {
    set_block(o, i, 0, plant.c * power);
    if (i + 1 < n) power = power * d.phi_h;
  }
  DenseMatrix en = DenseMatrix::zeros(n, 1);
  en(n - 1, 0) = 1.0;
  const SolveResult z = solve(o, en, 0.0);
  if (!z.ok) {
    d.deadbeat_unavailable_reason = "the observability matrix is singular";
    return;
  }
  const DenseMatrix k = power * z.x;
  // Verify: E = (I − K C)Φ must be nilpotent, Eⁿ = 0 to rounding.
  const DenseMatrix e = (identity(n) - k * plant.c) * d.phi_h;
  DenseMatrix en_pow = identity(n);
  for (std::size_t i = 0; i < n; ++i) en_pow = en_pow * e;
  const double scale = std::max(1.0, std::pow(max_abs(d.phi_h), static_cast<double>(n)));
  d.deadbeat_residual = max_abs(en_pow) / scale;
  if (!(d.deadbeat_residual <= 1e-8)) {
    d.deadbeat_unavailable_reason = "numerically ill-conditioned: ((I - K C) Phi)^n = " + sci(d.deadbeat_residual) +
                                    " (relative), not 0 (observability reciprocal condition " + sci(z.rcond) + ")";
    return;
  }
  d.deadbeat_gain = k;
  d.deadbeat = true;
}

}  // namespace oneshot::design::detail
