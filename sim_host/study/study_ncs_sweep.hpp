/// @file study_ncs_sweep.hpp
/// @brief `oneshot-sim study run` of an ncs study file: the engine's sweep (shards, merge)
///        over the file's approaches × scenarios × seeds, summarized with the keys of
///        `ncs table --json` plus per-link counters.
#pragma once

#include <cstddef>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "ncs_loop.hpp"
#include "oneshot/engine/sweep.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {

/// Names of the per-link counters, each a metric "<link>.<counter>" of the sweep.
inline constexpr const char* kLinkCounters[] = {"sent", "delivered", "lost", "late", "refused"};

/// Names of the delay metrics of a leg on a CAN bus, each a metric "<link>.<name>" of the
/// sweep: messages delivered over the bus, the smallest, largest and summed delay (µs, from
/// queued to the end of the message's last frame: queueing + transmission).
inline constexpr const char* kBusDelayMetrics[] = {"bus_messages", "bus_delay_min_us", "bus_delay_max_us", "bus_delay_sum_us"};

/// Names of the metrics of the controller's CPU (a file's `cpus`), each "cpu.<name>": its
/// jobs finished, their smallest, largest and summed response time τ_c (µs), its deadline
/// misses, the misses of the other tasks and ISRs, and the CPU's busy time (µs).
inline constexpr const char* kCpuMetrics[] = {"jobs", "response_min_us", "response_max_us", "response_sum_us",
                                              "deadline_misses", "other_misses", "busy_us"};
/// Metrics of the one-shot approaches (only in sweeps that run one): the filter's NEES (mean of
/// e_kᵀ P_k⁻¹ e_k over the run's computations, 0 for the approaches without a filter), its
/// computations, the sensor's samples and the samples it sent. Sweeps with filtered approaches
/// (ncs::filtered_approach()) but no one-shot one have the first two only.
inline constexpr const char* kOneShotMetrics[] = {"nees", "nees_steps", "sensor.samples", "sensor.sent"};
/// The leading NEES metrics of kOneShotMetrics: what every other filtered approach reports.
inline constexpr std::size_t kNeesMetricCount = 2;

/// Position of the counter `name` in kLinkCounters (its size when there is none).
constexpr std::size_t link_counter_index(std::string_view name) {
  std::size_t i = 0;
  while (i < std::size(kLinkCounters) && name != kLinkCounters[i]) ++i;
  return i;
}

/// The legs of the one loop `s` on a CAN bus, in the order of s.links (the same in every
/// scenario: overrides cannot move a leg).
std::vector<std::string> bus_links(const NcsStudy& s);

/// The header of a sweep of `s`: study "study", `experiment`, the file's approaches and
/// scenarios by name, its first seed, `seeds` replications (0: the file's count); no metrics.
engine::SweepSpec study_sweep_spec(const NcsStudy& s, std::size_t seeds, const char* experiment);

/// The sweep configuration of the one loop `s` (spec.config of a file without `loops`:
/// study_file, plant, links, compute_us, scenarios with their legs and bus legs, bus_links).
nlohmann::json loop_sweep_config(const NcsStudy& s);
/// The per-run metrics of the one loop `s`: cost, late, saturated, faults, per link the
/// kLinkCounters, per leg on a bus the kBusDelayMetrics.
std::vector<std::string> loop_sweep_metrics(const NcsStudy& s);
/// Run `r` of approach index `a` of `s` as the values of loop_sweep_metrics(); `on_bus` is
/// bus_links() of `s` (computed once per sweep).
std::vector<double> loop_sweep_values(const NcsStudy& s, std::size_t a, const ncs::RunResult& r, const std::vector<std::string>& on_bus);

/// The sweep of a file with several loops (s.loops; study_loops_sweep.cpp): each run is
/// ncs::run_loops() of every loop on the shared engine, and each loop once more alone on it
/// (the same seed: common random numbers), metrics "<loop>/<metric>" (loop_sweep_metrics())
/// (with SK or IK among the approaches also "<loop>/nees", "<loop>/nees_steps": the loop's
/// filter as in a file of one loop) and "<loop>/alone.cost", "<loop>/alone.<leg>.<bus delay
/// metric>"; the configuration {"study_file", "loops": [loop_sweep_config() + "name",
/// "addresses", "file_links", "clock_offset_us" when not 0, ...]}. `analytic` is refused
/// (engine::InputError naming `--analytic`). `share_caches` as run_ncs_sweep(): every loop's
/// plant, in the shared run and alone, takes its caches from the sweep's pool of its shape.
engine::SweepResults run_loops_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard,
                                     bool analytic, bool share_caches = true);

/// The loops of `s` (a file with several loops) on scenario index `scenario`, for ncs::run_loops().
std::vector<ncs::LoopOnBus> loops_on_bus(const NcsStudy& s, std::size_t scenario);

/// Loop `i` of the sweep of a file with several loops as the sweep of a one-loop file (its
/// metrics without the "<loop>/" prefix, its configuration; the alone runs left out).
engine::SweepResults loop_results(const engine::SweepResults& results, std::size_t i);

/// The summary of a complete sweep of several loops: "loops": per loop run_outputs() of
/// loop_results() (files in out_dir/<loop>), "interference": per loop and approach the paired
/// comparison of the loop's cost on the shared bus against alone on it (per seed the scenario
/// mean of shared − alone: mean, ci95; ratio shared / alone), and per leg on a bus the observed
/// delays (messages, min_us, mean_us, max_us) shared and alone beside the check's worst-case
/// response (counting every loop's frames) and within_bound; "markdown" every loop's table and
/// the interference tables ("markdown_interference" these alone); "order_text" per loop.
nlohmann::json loops_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

/// Runs the sweep (or one shard) of `s` with `seeds` replications (0: the file's count) on
/// `threads` threads (0: every core). The runs are ncs::run() on the file's scenarios: same
/// seeds, same random stream names, so the same costs as `ncs table` on the same settings.
/// With `analytic` (`study run --analytic`), as `ncs table --analytic`: beside each run the
/// same run in ncs::RunOptions::analytic mode, its exact E[J] over the noise for the run's
/// timing in the metrics "analytic", "analytic_refused" (the refusal's code, 0 when valid) and
/// "analytic_mismatch", and "analytic": true in the configuration (only then: the sweep's
/// spec, and its shards, stay as they are without). With `share_caches` the runs of each
/// thread take the plant's interval maps and noise terms from one pool for the sweep, per
/// plant shape (ncs::RunOptions::caches, ncs::ShapeCachePools); without, each run its own: the
/// same bytes either way.
engine::SweepResults run_ncs_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard,
                                   bool analytic = false, bool share_caches = true);

/// The summary of a complete sweep: ncs::table_outputs() (cost_mean, cost_ci95, ratio_to_I,
/// ratio_scenario_weighted, paired differences, per scenario; with an analytic sweep the
/// keys of ncs::analytic_outputs(), refused approaches with their reason; files in `out_dir`) plus
/// "links": per approach and link the totals of sent, delivered (not lost: arrived or in
/// flight at the end), lost, late (dropped by the receiver as stale: not newer than what it
/// holds, or after its period; the periods without a command are the approach's
/// late_commands, not frames) and refused
/// (refused by the receiver's frame checks) over every run; "delay_bound_sc_ca_ms": per
/// scenario the upper bound of the sc + ca delays (null when a leg is unbounded). ncs table's
/// S_ratio_to_I_by_delay_ms and S_ratio_increases_with_delay are left out: they are keyed by
/// study ncs's d (every leg U[0.5, d] ms), which a file's legs do not have. With legs on a
/// CAN bus, "bus_delays": per approach and leg the messages, min_us, mean_us, max_us of the
/// observed delays (queueing + transmission) over every run, the check's worst_response_us
/// (the largest over the scenarios; null when unbounded), within_bound, and per_scenario the
/// same; their table is appended to "markdown". With the controller on a CPU, "cpu": per
/// approach the controller job's jobs and observed response min_us, mean_us, max_us beside
/// the analysis's wcrt_us and bcrt_us, within_bounds, deadline_misses, other_misses (the
/// CPU's other tasks and ISRs) and the measured utilization (busy time / simulated time;
/// I and IK do not use the CPU: 0 jobs); its table is appended to "markdown" and is
/// "markdown_cpu".
/// With approaches that run a Kalman filter (ncs::filtered_approach()), "nees": per such
/// approach nees_mean, nees_ci95 (over seeds of the scenario mean), steps (the filter
/// computations averaged) and per_scenario nees_mean, nees_ci95 (table appended to "markdown").
/// With one-shot approaches, "one_shot": per
/// such approach nees_mean, nees_ci95 (over seeds), samples, sent, send_rate and per_scenario
/// the same (table appended to "markdown").
nlohmann::json run_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);

}  // namespace oneshot::study
