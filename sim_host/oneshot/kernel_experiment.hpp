/// @file kernel_experiment.hpp
/// @brief `oneshot-sim oneshot kernel`: the reference loop's control job as one task on a
///        dsPIC33-class CPU beside other control loops and background tasks (the engine's CPU
///        model, issue 22); the schedule produces the jitter of approaches A–E.
///
/// Per configuration (CPU utilization U × the control task's priority) and seed, the CPU is
/// simulated for the scenario's duration; the control job samples at its sample point
/// (`--sample-at`, default its start: latency sample − k·h) and the standard approaches
/// actuate at its actuation point (`--actuate-at`, default its end: actuation − sample later),
/// the one-shot approaches at the next period boundary through the timer ISR (the ISR is in
/// the task set). Those per-job timings are the scenario's jitter trace; A runs without
/// jitter (the reference). Every approach of a seed sees the same schedule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/cpu_task_set.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot_experiments.hpp"

namespace oneshot::sim {

/// The experiment's CPU and sweep.
struct KernelExperimentOptions {
  double clock_mips = 40;              ///< dsPIC33FJ256MC710 of the reference board: 40 MIPS.
  std::string exectime_file;           ///< `oneshot-sim exectime --target cortex-m0 --json FILE` output (empty: assumption).
  std::string variant = "half_table_fixed";  ///< Job variant read from it.
  std::vector<double> utilizations = {0.3, 0.45, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95};  ///< CPU utilization grid.
  std::int64_t context_switch_us = 2;  ///< Erika context switch (assumption: ~80 cycles at 40 MIPS).
  std::uint64_t isr_instructions = 120;  ///< Actuation timer ISR (assumption: PWM write + flag).
  double duration_s = 20;              ///< Simulated time per run.
  std::size_t seeds = 20;              ///< Seeds (as Table I).
  engine::Shard shard;                 ///< Part of the sweep.
  engine::cpu::JobPoint sample_at = engine::cpu::job_start();  ///< Control job: where it reads the input.
  engine::cpu::JobPoint actuate_at = engine::cpu::job_end();   ///< Where it writes the output (standard approaches).
};

/// Where the control task sits among the other tasks.
enum class ControlPriority : std::uint8_t { kHighest, kRateMonotonic, kLowest };

/// Name of a priority position ("highest", "rate_monotonic", "lowest").
const char* to_string(ControlPriority p);

/// The CPU of one configuration: the actuation-timer ISR, the control task "control" (period
/// h, execution `job`, sample and actuation points from `k`), and six others scaled so that Σ C/T = `utilization` (rate-monotonic
/// among themselves): uart_rx (sporadic 2–6 ms), comm 5 ms, loop_fast 7 ms, loop_mid 13 ms,
/// logger 31 ms, diag 97 ms; their jobs uniform in [C/2, C].
engine::cpu::TaskSet kernel_task_set(const engine::cpu::ExecModel& job, std::int64_t period_us, double utilization,
                                     ControlPriority position, const KernelExperimentOptions& k);

/// The control job's execution-time model at the stated clock: from the exectime file's
/// variant (instructions_per_job_min … max), or the study's stated assumption (uniform
/// 200–600 µs, scenario.hpp) when no file is given.
engine::cpu::ExecModel control_job_model(const KernelExperimentOptions& k);

/// Runs the sweep (or its shard) and writes kernel.md, kernel.csv, kernel.png, one task file.
nlohmann::json run_kernel_experiment(const SimContext& ctx, const CommonOptions& opt, const KernelExperimentOptions& k);

/// The summary and files of a complete sweep (also the merge summarizer).
nlohmann::json kernel_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

}  // namespace oneshot::sim
