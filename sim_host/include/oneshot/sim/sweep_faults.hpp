/// @file sweep_faults.hpp
/// @brief A study table run under a fault spec (`--inject`, docs/faults.md): the per-run
///        fault metrics appended to its sweep and their per-row summary in the JSON.
///
/// The metrics and the spec's text (config "inject") are added only when the spec is not
/// empty, so the clean table's spec, shards and outputs stay as they were. Each faulted run
/// also runs the clean run of its seed: `ratio_to_clean` is the study's figure of merit
/// (config "inject_ratio_of") of the faulted run over the clean run's, paired per seed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/sweep.hpp"

namespace oneshot::sim {

/// Counters of one faulted run (summed over the run's receiving nodes).
struct RunFaultCounts {
  double injected = 0;              ///< Faults injected (engine::FaultCounters::injected()).
  double corrupt = 0;               ///< Frames refused: CRC-16 mismatch (bits altered on the way).
  double refused_non_finite = 0;    ///< Frames refused: a value not finite.
  double refused_out_of_range = 0;  ///< Frames refused: a value outside the design's range.
  double refused_sequence = 0;      ///< Frames refused: sequence number outside its window.
  double stale = 0;                 ///< Frames dropped as not newer than the last (dup, replay).
  double estimator_resets = 0;      ///< Estimates that turned non-finite (see the study's page).
  double ratio_to_clean = 0;        ///< Figure of merit over the clean run's (same seed).
};

/// The metric names of RunFaultCounts, in its order.
const std::vector<std::string>& fault_metric_names();

/// With a non-empty spec: records its text (config "inject") and what `ratio_of` names
/// (config "inject_ratio_of") and appends fault_metric_names() to the metrics. Nothing otherwise.
void add_fault_metrics(engine::SweepSpec& spec, const engine::FaultSpec& faults, const std::string& ratio_of);

/// Appends the counters in metric order to a run's values.
void append_fault_values(std::vector<double>& values, const RunFaultCounts& c);

/// Row (approach a, scenario s) of a faulted table: per metric {mean, ci95} over the seeds
/// over its finite values, with their count "n" (a mean or interval that overflows, e.g. the
/// ratio of two diverged runs: null); null for a clean table.
nlohmann::json fault_row(const engine::SweepResults& r, std::size_t a, std::size_t s);

/// Markdown table of a faulted table's rows (every approach × scenario): the spec, the
/// counters per run and ratio_to_clean (mean ± 95 % CI, finite runs of all); "" for a clean table.
std::string fault_markdown(const engine::SweepResults& r);

}  // namespace oneshot::sim
