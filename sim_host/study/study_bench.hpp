/// @file study_bench.hpp
/// @brief What `oneshot-sim study bench` reports for any study file's timed sweep: events, wall
///        and CPU time, events per second per thread and per CPU second, per approach its runs'
///        events over their time on their thread (docs/study-files.md, Speed).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

/// The figures of a timed sweep `r` whose metrics include "events" (kernel events of the run),
/// "simulated_s" (its simulated seconds) and "run_s" (its time on its thread): per approach
/// {events, run_s, events_per_run_s = events / run_s}; study_file `source`, runs, seeds,
/// threads, events, simulated_s, wall_s, cpu_s, events_per_s = events / wall_s,
/// events_per_s_per_thread = events / wall_s / threads, events_per_cpu_s = events / cpu_s
/// (0 when a time is 0).
nlohmann::json bench_figures(const engine::SweepResults& r, const std::string& source, unsigned threads, double wall_s,
                             double cpu_s);

/// The mean of metric `metric` (one of r.spec.metrics) over approach `approach`'s runs of `r`,
/// every scenario x seed: (1 / (S K)) sum_x sum_k r.at(approach, x, k, metric), summed scenario
/// by scenario, seed by seed.
double mean_of(const engine::SweepResults& r, std::size_t approach, const std::string& metric);

/// What one run of a timed sweep gives: its cost, its kernel events, its simulated seconds.
struct BenchRun {
  double cost = 0;         ///< The run's cost (the study's `cost` metric).
  double events = 0;       ///< Its kernel events (queue pops).
  double simulated_s = 0;  ///< Its simulated seconds.
};

/// One run of a timed sweep: approach `a`, scenario `x`, seed `seed`.
using BenchRunFn = std::function<BenchRun(std::size_t a, std::size_t x, std::uint64_t seed)>;

/// `study bench` of a study file other than ncs: the sweep `spec` (its metrics set here to cost,
/// events, simulated_s, run_s) run with `run` on `threads` threads (0: every core) and timed
/// (wall and process CPU time; each run's own time on its thread); bench_figures() plus per
/// approach the mean cost over its runs (`cost_mean`, null when not finite). `label` names the
/// sweep in its errors.
nlohmann::json timed_bench(engine::SweepSpec spec, unsigned threads, const std::string& source, const BenchRunFn& run,
                           const char* label);

struct NcsStudy;
struct DroppingStudy;

/// `study bench` of an ncs file: its sweep (approaches x scenarios x seeds, ncs::run with the
/// sweep's seeds; a file with several loops: ncs::run_loops, one run of them all) timed, each
/// run's kernel events counted (an event: one pop of the engine's event queue, whatever its
/// handler: sampling, timers, computations, deliveries, set-point switches, CAN frames and
/// background traffic); bench_figures() plus per approach the mean cost over its runs
/// (`cost_mean`; a file with several loops: `loops.<loop>.cost_mean`).
nlohmann::json ncs_bench(const NcsStudy& s, std::size_t seeds, unsigned threads);

/// `study bench` of a dropping file: its sweep as `study run` runs it (dropping::run_closed_loop
/// with the sweep's seeds) timed, each run's kernel events counted (the engine's queue pops:
/// plant steps, samples, computations, deliveries); bench_figures() plus per approach the mean
/// cost over its runs (`cost_mean`, null when a run diverged).
nlohmann::json dropping_bench(const DroppingStudy& s, std::size_t seeds, unsigned threads);

/// The line `study bench` prints for the figures `j` of `file`.
std::string bench_line(const std::string& file, const nlohmann::json& j);

}  // namespace oneshot::study
