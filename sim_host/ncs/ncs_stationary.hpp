/// @file ncs_stationary.hpp
/// @brief Study ncs, stationary cost per second for i.i.d. delays (the Jitterbug method) on
///        the engine's stationary_cost(): the approaches whose gains do not depend on the delay
///        history, with their firmware laws probed as in the analytic mode (ncs_analytic.hpp).
///
/// Per period the timing of these loops is one number drawn independently of the other periods:
///  - S, S+, SK: sample at kh, command applied at kh + τ, τ = τ_sc + τ_c + τ_ca (the three
///    discrete uniforms of the scenario in whole µs, convolved exactly);
///  - A: request at t_{k−1}, sample at t_{k−1} + τ_as, x̂_k predicted over h − τ_as, applied at t_k;
///  - IK: no delay (one case).
/// The distribution is put on a grid of `grid_us` (each whole-µs value to the nearest grid
/// point, a tie split between both, so mass and mean are kept); every grid point is a case of stationary_cost(), its period run by an
/// AnalyticTracker on the node's own law or predictor (SK's filter first run to its stationary
/// gain). AK, AKx, AKl are refused (the half Kalman's P, hence its gain, depends on the delay
/// history: not a jump-linear system with i.i.d. modes), I too (it has no noise: cost 0).
/// The cost is the noise-driven part only (reference zero): the table's J also holds the
/// set-point transients. Checked against long analytic runs of the study's own loop:
/// (E[J](T₂) − E[J](T₁)) / (T₂ − T₁) of the covariance and noise-path parts, per seed.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ncs_model.hpp"

namespace oneshot::ncs {

/// A delay distribution on a grid: values (µs) and their probabilities.
struct DelayPmf {
  std::vector<std::int64_t> tau_us;  ///< Grid points with mass, ascending.
  std::vector<double> p;             ///< Their probabilities (sum 1).
};

/// The pmf of the sum of discrete uniforms U{lo_i … hi_i} (whole µs), exactly, then moved to
/// the nearest multiple of `grid_us` (≥ 1; ties split in halves).
DelayPmf uniform_sum_pmf(const std::vector<std::pair<std::int64_t, std::int64_t>>& ranges, std::int64_t grid_us);

/// The timing distribution of approach `a` on scenario `sc` (see the file comment).
DelayPmf timing_pmf(const Context& ctx, const Scenario& sc, Approach a, std::int64_t grid_us);

/// Why `a` has no stationary cost here ("" when it has).
std::string stationary_refusal(Approach a);

/// Stationary result of one approach on one scenario.
struct StationaryRow {
  double cost_rate = 0;        ///< J per second, noise-driven part.
  double spectral_radius = 0;  ///< Of the covariance map (< 1).
  double residual = 0;         ///< Relative residual of the linear equations.
  std::size_t cases = 0;       ///< Grid points.
};

/// The stationary cost of `a` on `sc` (std::invalid_argument with the refusal).
StationaryRow stationary_row(const Context& ctx, const Scenario& sc, Approach a, std::int64_t grid_us);

/// Long analytic runs: per seed (E[J](T₁ + span) − E[J](T₁)) / span of the covariance and
/// noise-path parts (T₁ = warm_s), the mean and 95 % half-width over `seeds` seeds from `first_seed`.
std::pair<double, double> long_run_rate(const Context& ctx, const Scenario& sc, Approach a, std::uint64_t first_seed,
                                        std::size_t seeds, double warm_s, double span_s, unsigned threads);

/// Options of `ncs stationary`.
struct StationaryOptions {
  std::vector<Scenario> scenarios = default_scenarios();  ///< Scenarios.
  std::vector<Approach> approaches = {Approach::kIK, Approach::kA, Approach::kSPlus, Approach::kSK, Approach::kS};
  std::int64_t grid_us = 100;  ///< Grid of the delay distribution.
  std::size_t check_seeds = 8; ///< Long analytic runs per approach and scenario (0: none).
  double check_warm_s = 20;    ///< T₁.
  double check_span_s = 100;   ///< T₂ − T₁.
  std::uint64_t seed = 1;      ///< First seed of the check.
  unsigned threads = 0;        ///< Worker threads (0: every core).
};

/// `ncs stationary`: per scenario and approach the stationary cost per second, the long-run check,
/// refusals with their reason, and a markdown table (key "markdown").
nlohmann::json stationary_table(const Context& ctx, const StationaryOptions& o);

}  // namespace oneshot::ncs
