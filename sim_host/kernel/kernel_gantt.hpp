/// @file kernel_gantt.hpp
/// @brief Outputs of `oneshot-sim kernel simulate`: the simulation summary, the Gantt chart
///        of the first hyperperiod (CSV and gnuplot PNG) and the event log.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/cpu.hpp"

namespace oneshot::sim {

/// Where `kernel simulate` writes its files.
struct KernelOutputs {
  std::string out_dir;   ///< gantt.csv, gantt.gp, gantt.png (empty: no Gantt).
  std::string log_path;  ///< Event log CSV (empty: none).
  bool plots = true;     ///< Draw gantt.png with gnuplot.
};

/// The first hyperperiod of a task set: the largest offset plus the lcm of the periods of its
/// periodic tasks and ISRs, capped at 1 s (the chart's span).
engine::Duration first_hyperperiod(const engine::cpu::TaskSet& set);

/// Writes gantt.csv (row, task, start_ms, end_ms per execution segment in [0, span]) and, with
/// `plots`, gantt.png; returns {"span_us", "segments", "files"}.
nlohmann::json write_gantt(const engine::cpu::Cpu& cpu, engine::Duration span, const std::string& dir, bool plots);

/// Simulates `set` for `duration_s` with `seed` and summarizes every task and ISR (JSON of
/// `kernel simulate`); the wall time of the run goes to `wall_time_s` when given.
nlohmann::json kernel_simulate(const engine::cpu::TaskSet& set, double duration_s, std::uint64_t seed,
                               const KernelOutputs& out, double* wall_time_s = nullptr);

}  // namespace oneshot::sim
