/// @file sod_design.hpp
/// @brief The δt design of modified send-on-delta (send-on-delta brief §5, eqs 5–11).
///
///     d̄_i   = δt,i ξ_i / ΔT_i                                     (7)
///     R̄(δt) = R + diag(((d̄_i + 1) δy,i)² / 3)                     (9)
///     P(δt) = stabilising solution of the prior DARE with R̄        (10)
///     min f = Σ_i 1/δt,i   s.t.  P_ii(δt) ≤ μ P0_ii,  P0 = P(d̄ = 0) (11)
/// The constraints depend on δt only through d̄, so the search runs in d̄ and
/// δt*_i = d̄*_i ΔT_i / ξ_i: with ξ1 = ξ2 and ΔT fixed, δt*·ξ does not depend on ξ. P grows
/// with every R̄_jj, so the feasible set is closed downward: for each d̄_1 the largest
/// feasible d̄_2 is found by bisection (∞ when the constraints hold with node 2's
/// measurement gone), f is minimized along that edge (log grid, then golden section) and
/// checked against a grid of the plane. d̄_i = ∞ means node i's R̄ → ∞ (its measurement
/// carries nothing); when the constraints still hold there, δt*_i is unbounded and
/// reported as such with the reason — rule (2b) off for that node.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sod_model.hpp"

namespace oneshot::sod {

/// Inputs of the δt design.
struct DesignInputs {
  double delta_y[kNodes] = {0.5, 0.5};  ///< δy,i.
  double loss[kNodes] = {0.05, 0.05};   ///< ξ_i.
  double mean_gap_s[kNodes] = {1, 1};   ///< ΔT_i: mean time between plain-SOD packets (s).
  double mu = 5;                        ///< Bound factor μ.
};

/// One node's result.
struct NodeDeltaT {
  bool bounded = true;        ///< False: δt*_i = ∞ (rule 2b off).
  double dbar = 0;            ///< d̄*_i (∞ when unbounded).
  double delta_t_s = 0;       ///< δt*_i (s), when bounded.
  std::uint32_t n_t = 0;      ///< round(δt*_i / T) (0 when unbounded).
  double delta_t_times_loss = 0;  ///< δt*_i·ξ_i (s), when bounded.
  std::string reason;         ///< Why unbounded (empty otherwise).
};

/// The design's result.
struct DeltaTDesign {
  double p0_diag[kNodes] = {};       ///< diag P0 (prior, d̄ = 0).
  double p_diag[kNodes] = {};        ///< diag P(δt*).
  NodeDeltaT node[kNodes];           ///< Per node.
  double packets_per_s = 0;          ///< f(δt*) = Σ 1/δt*_i.
  std::vector<std::string> active;   ///< Binding constraints ("P11 <= mu P0_11", …); empty when none binds.
  double grid_best_packets_per_s = 0;  ///< Best feasible f on the check grid.
  bool grid_check_passed = false;    ///< f(δt*) ≤ grid best (within 1e-9 relative).
  std::size_t riccati_solves = 0;    ///< DARE solves spent.
};

/// diag of the prior DARE solution with R̄ = R + diag(((d̄_i + 1) δy,i)²/3); d̄_i = ∞ drops
/// node i (no measurement); std::runtime_error when the DARE fails.
std::vector<double> prior_riccati_diag(const SodModel& model, const double (&delta_y)[kNodes], const double (&dbar)[kNodes]);

/// Runs the §5 design; std::invalid_argument on bad inputs (μ ≤ 1, ξ outside [0, 1), ΔT ≤ 0).
DeltaTDesign design_delta_t(const SodModel& model, const DesignInputs& in);

}  // namespace oneshot::sod
