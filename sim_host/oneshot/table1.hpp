/// @file table1.hpp
/// @brief Table I of the one-shot study (experiment 4) as an engine sweep: approaches A–E
///        × scenarios × seeds, shardable, summarized from the raw costs alone.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "oneshot_experiments.hpp"

namespace oneshot::sim {

/// The sweep of Table I: metrics "cost" (J) and "saturated" (1 when the fixed-point flag
/// was raised); `config` holds the plant digest, the job options and every scenario.
engine::SweepSpec table1_spec(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                              std::size_t seeds);

/// Runs the shard of Table I (all of it by default) on opt.threads threads; the wall time
/// goes to `wall_time_s` when given, never into the results.
engine::SweepResults table1_sweep(const SimContext& ctx, const CommonOptions& opt,
                                  const std::vector<Scenario>& scenarios, std::size_t seeds,
                                  const engine::Shard& shard, double* wall_time_s);

/// The Table I summary JSON and its files (table1.md, table1.csv, table1_runs.csv,
/// table1.png) in `out_dir`, from a complete sweep: everything comes from the sweep, so a
/// merge of shards writes the same bytes as one run.
nlohmann::json table1_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

}  // namespace oneshot::sim
