/// @file ncs_experiments.hpp
/// @brief Experiments of study `ncs`: E4 (the table on the engine's sweep, shards and
///        merge) and E1–E3 (traces and plots).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ncs_model.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/sweep.hpp"

namespace oneshot::ncs {

/// Options of the table (E4).
struct TableOptions {
  std::size_t seeds = 50;          ///< Seeds per scenario (≥ 2).
  std::uint64_t first_seed = 1;    ///< Seed of the first replication.
  bool noise_free = false;         ///< No noise: the invariant A = I, S degrading with d.
  unsigned threads = 0;            ///< Worker threads (0: every core).
  std::vector<Approach> approaches{kAllApproaches.begin(), kAllApproaches.end()};  ///< I must be first.
  std::vector<Scenario> scenarios;  ///< Scenarios (empty: the ten defaults, with duration_s).
  double duration_s = 20;          ///< Run length per default scenario.
  engine::FaultSpec faults;        ///< Faults injected in every run (empty: clean).
  bool analytic = false;           ///< Also E[J] over the noise per run's timing (ncs_analytic.hpp).
};

/// Runs the table's sweep (or one shard of it).
engine::SweepResults table_sweep(const Context& ctx, const TableOptions& opt, const engine::Shard& shard);
/// The table's summary from a complete sweep: JSON (cost_mean, cost_ci95, ratio_to_I,
/// ratio_scenario_weighted with CI, paired differences, per scenario, the order measured,
/// and with --noise-free the invariant checks) and files in `out_dir` (CSV, markdown, plot).
nlohmann::json table_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

/// Markdown of the paired differences of a table_outputs() JSON: a row (mean, 95 % CI over
/// seeds) for each pair "X-Y" of `pairs` the table has, in that order.
std::string paired_differences_markdown(const nlohmann::json& table, const std::vector<std::string>& pairs);

/// The cost part of a report section from a table_outputs() JSON: the table (mean cost with
/// its 95 % CI, ratios to I with theirs), the order by mean cost, the paired differences of
/// `pairs` and, when `plot_path` is not empty, the cost bars (with intervals) it links to.
std::string table_section_markdown(const nlohmann::json& table, const std::vector<std::string>& pairs,
                                   const std::string& plot_path);

/// E1 (Fig. 6): noisy y1, y2 beside AK's estimates on one run; files in out_dir.
nlohmann::json run_e1(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots);
/// E2 (Fig. 7): delays only, I, S and A on the square wave; files in out_dir.
nlohmann::json run_e2(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots);
/// E3 (Fig. 8): delays, noise and disturbance, S, A and AK; files in out_dir.
nlohmann::json run_e3(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots);

}  // namespace oneshot::ncs
