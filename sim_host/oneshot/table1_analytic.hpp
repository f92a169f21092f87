/// @file table1_analytic.hpp
/// @brief `oneshot-sim table1 --analytic`: Table I on the linear board (linear_board.hpp) with
///        the exact expected cost per timing draw beside the Monte Carlo of the same model and
///        the emulated board's normal Table I cost.
///
/// Per run (approach, scenario, seed) three simulations share the seed's timing, set-point and
/// noise streams: the linear board noise-free with its analytic tracker (E[J] over the noise),
/// the linear board with noise (one Monte Carlo draw), and the emulated board (the normal
/// Table I run with the command's options). Keys per approach: analytic_mean, analytic_ci95
/// (95 % interval over the timing draws), cost_mean, cost_ci95 (the linear board's Monte
/// Carlo), board_cost_mean, board_cost_ci95, quantization_cost (board − linear, paired),
/// variance_reduction = (cost_ci95 / analytic_ci95)²; per scenario B/A (paired per seed) and
/// whether B lies within 0.2 % of A: "yes" when the whole interval of B/A − 1 is below 0.2 %,
/// "no" when it is wholly above, "undecided" otherwise.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "oneshot_experiments.hpp"

namespace oneshot::sim {

/// The B/A tolerance the per-scenario decision tests (0.2 %).
inline constexpr double kWithinTolerance = 0.002;

/// "yes", "no" or "undecided" for an interval [mean − ci95, mean + ci95] of B/A − 1 against `tol`.
const char* decide_within(double mean, double ci95, double tol);

/// Runs the analytic Table I (every run; no shards) on opt.threads threads; the wall time goes
/// to `wall_time_s` when given.
engine::SweepResults table1_analytic_sweep(const SimContext& ctx, const CommonOptions& opt,
                                           const std::vector<Scenario>& scenarios, std::size_t seeds,
                                           double* wall_time_s);

/// The summary JSON (keys in the file comment) and table1_analytic.md, table1_analytic_runs.csv in `out_dir`.
nlohmann::json table1_analytic_outputs(const engine::SweepResults& results, const std::string& out_dir);

/// Sweep and outputs.
nlohmann::json run_table1_analytic(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                                   std::size_t seeds, double* wall_time_s);

}  // namespace oneshot::sim
