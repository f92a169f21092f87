/// @file sweep_statistics.hpp
/// @brief Summaries of a sweep's metric: means with 95 % intervals over seeds, ratios to a
///        reference approach, per-scenario figures and paired differences between approaches.
///
/// Seeds are the independent replications: for each seed k the scenario mean
///     m_a,k = (1/S) Σ_s v_a,s,k
/// is one observation of approach a; its mean over seeds has a Student-t interval. Because
/// every approach of a seed sees the same random draws, approaches are compared per seed:
///     ratio_a,k = m_a,k / m_ref,k,   weighted_a,k = (1/S) Σ_s v_a,s,k / v_ref,s,k,
///     diff_ab,k = m_a,k − m_b,k,
/// each summarized by its mean and t interval over seeds (a paired comparison, much tighter
/// than the difference of two unpaired intervals). The weighted ratio gives every scenario
/// one vote whatever its magnitude. Every sum runs in index order, so the same values give
/// the same bits.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::engine {

using util::Summary;

/// Summary of one metric of a complete sweep.
struct SweepSummary {
  std::size_t metric = 0;                         ///< Metric index.
  std::size_t reference = 0;                      ///< Reference approach index.
  std::vector<std::vector<double>> per_seed;      ///< [a][k] scenario mean m_a,k.
  std::vector<Summary> value;                     ///< [a] over seeds of m_a,k.
  std::vector<double> ratio_of_means;             ///< [a] mean(m_a) / mean(m_ref).
  std::vector<Summary> ratio;                     ///< [a] over seeds of m_a,k / m_ref,k.
  std::vector<Summary> ratio_weighted;            ///< [a] over seeds of the scenario-weighted ratio.
  std::vector<std::vector<Summary>> per_scenario; ///< [a][s] over seeds of v_a,s,k.
  std::vector<std::vector<Summary>> per_scenario_ratio;  ///< [a][s] over seeds of v_a,s,k / v_ref,s,k.
  /// Paired difference a − b (a < b) over seeds.
  struct Pair {
    std::size_t a = 0;  ///< First approach.
    std::size_t b = 0;  ///< Second approach.
    Summary diff;       ///< Mean and CI of m_a,k − m_b,k.
  };
  std::vector<Pair> paired;                       ///< Every pair a < b.
  bool reference_has_zero = false;                ///< Some reference value is 0: ratios undefined (NaN).
};

/// Summarizes metric `metric` of a complete sweep against approach `reference`.
SweepSummary summarize_metric(const SweepResults& results, std::size_t metric, std::size_t reference);

/// The summary as JSON: {"metric", "reference", "approaches": {name: {mean, ci95,
/// ratio_to_reference, ratio_mean, ratio_ci95, ratio_scenario_weighted,
/// ratio_scenario_weighted_ci95}}, "per_scenario": [{name, approaches: {name: {mean, ci95,
/// ratio_mean, ratio_ci95}}}], "paired_differences": {"a-b": {mean, ci95}}}; undefined
/// ratios are null.
nlohmann::json summary_json(const SweepResults& results, const SweepSummary& summary);

/// The paired differences of `summary` as JSON: {"<a>-<b>": {"mean", "ci95"}} for every pair
/// a < b (names in the sweep's order), diff_ab = mean_k (m_a,k − m_b,k); a non-finite mean or
/// interval (a diverged run) is null. Empty object for a single approach.
nlohmann::json paired_differences_json(const SweepResults& results, const SweepSummary& summary);

/// The approaches ordered by their mean over seeds, ascending (std::stable_sort of (mean, name)
/// pairs: equal means by name): {"order_by_mean_cost": [names], "order_text": "a < b < ..."}
/// merged into `j` (the keys of `ncs table --json`).
void add_order_by_mean(nlohmann::json& j, const SweepResults& results, const SweepSummary& summary);

/// Writes the raw runs as CSV: approach_index, scenario_index, seed, one column per metric;
/// a NaN or infinite value is refused unless `non_finite` is kMissing (a divergence the study reports).
void write_runs_csv(const SweepResults& results, const std::string& path,
                    util::NonFinite non_finite = util::NonFinite::kRefuse);

/// Writes DIR/PREFIX_runs.csv (raw runs), DIR/PREFIX_summary.csv (approach_index, mean,
/// ci95, ratio_mean, ratio_ci95 of the summarized metric) and, with `plots`, DIR/PREFIX.png
/// (bars with 95 % intervals, drawn by gnuplot).
void write_summary_files(const SweepResults& results, const SweepSummary& summary, const std::string& dir,
                         const std::string& prefix, bool plots);

}  // namespace oneshot::engine
