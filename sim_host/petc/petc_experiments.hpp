/// @file petc_experiments.hpp
/// @brief The petc study's experiments: the case table (sweep over seeds), the GPI surface
///        with its Pareto front, and the d / d̂ / N traces (figs 10 and 12 of the original).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/sweep.hpp"
#include "petc_sim.hpp"

namespace oneshot::sim::petc {

/// Options of a sweep experiment.
struct SweepOptions {
  std::size_t seeds = 20;         ///< Seeds (≥ 2).
  std::uint64_t first_seed = 1;   ///< Seed of the first run.
  unsigned threads = 0;           ///< Worker threads (0: all cores).
  std::string out_dir = "out/petc";  ///< Output folder.
  bool plots = true;              ///< Draw PNGs with gnuplot.
  engine::Shard shard;            ///< Part of the sweep to run.
  engine::FaultSpec faults;       ///< table: frame faults and restarts in every run (docs/faults.md).
};

/// The options and design digest that fix a sweep's numbers (its spec config).
nlohmann::json setup_config(const PetcSetup& setup);

/// Cases 1–6, 6′ over seeds; the summary JSON (or the shard file's JSON for a partial shard).
nlohmann::json run_table(const PetcSetup& setup, const SweepOptions& opt);

/// The table's summary from complete results (also the merge summarizer).
nlohmann::json table_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

/// GPI over δ_s = σ_s × δ_c = σ_c (case-4 setting) on a `grid` × `grid` log grid.
nlohmann::json run_gpi(const PetcSetup& setup, const SweepOptions& opt, std::size_t grid);

/// The GPI summary from complete results (also the merge summarizer).
nlohmann::json gpi_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

/// d, d̂, y, u and the sends against time for cases 4, 5, 6, 6′ (one seed): CSV + PNG.
nlohmann::json run_traces(const PetcSetup& setup, std::uint64_t seed, const std::string& out_dir, bool plots);

/// Markdown table of the case summary JSON (for the report section).
std::string table_markdown(const nlohmann::json& table);

}  // namespace oneshot::sim::petc
