/// @file experiments.hpp
/// @brief The experiments of the brief (§7) and the user's own runs; each writes CSV files
///        and PNG plots into an output folder and returns a JSON summary.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "scenario.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// Options shared by every experiment.
struct CommonOptions {
  std::string out_dir = "out";                            ///< Output folder.
  NumberFormat format = NumberFormat::kFloat;              ///< Job number format.
  DiscretizerKind discretizer = DiscretizerKind::kTable;   ///< One-shot Φ/Γ/Q_d source.
  NoiseModel noise = NoiseModel::kExact;                   ///< Constant Q or exact Q_d.
  BoardOptions board;                                      ///< Emulator options.
  unsigned threads = 0;                                    ///< Worker threads (0: every core).
  bool plots = true;                                       ///< Draw PNG plots with gnuplot.
  std::uint64_t seed = 1;                                  ///< Seed (first seed for sweeps).
};

/// The run options of approach `a` under the common options (format, discretizer, noise, board).
RunOptions run_options(const CommonOptions& opt, Approach a);

/// The file `name` in the experiment's output folder.
std::string path_in(const CommonOptions& opt, const std::string& name);

/// What every experiment's JSON summary starts with: plant, number format, discretizer, noise
/// model and seed.
nlohmann::json common_json(const SimContext& ctx, const CommonOptions& opt);

/// Experiment 1: noisy measured v1 beside the estimated states (half Kalman, one-shot).
nlohmann::json run_noise_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s);

/// Experiment 2: one-shot + half Kalman against standard controllers under jitter.
nlohmann::json run_jitter_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s,
                                     std::int32_t jitter_us);

/// Experiment 3: first Kalman gain element over time (half, complete, standard without jitter).
nlohmann::json run_gain_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s,
                                   double p0_scale);

/// Experiment 4: approaches A–E on the scenarios, `seeds` seeds each, 95 % intervals and
/// paired differences (sim_host/oneshot/table1.cpp). The JSON holds no wall time (it would
/// differ between identical runs): `wall_time_s` receives it when given. With a shard
/// other than 0/1 only that part runs: its raw results go to
/// OUT/table1.shard-i-of-N.json, and the shard JSON is returned (merge them with
/// `oneshot-sim merge`).
nlohmann::json run_table1(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                          std::size_t seeds, const engine::Shard& shard = {}, double* wall_time_s = nullptr);

/// Experiment 5: execution time of the control job, half/complete × table/generic, over
/// the jobs of 4 s of operation: steady-clock time on this host, and instruction counts
/// under valgrind (callgrind) when available.
nlohmann::json run_exectime(const SimContext& ctx, const CommonOptions& opt, const std::string& self_path);

/// The hidden half of run_exectime: replays one variant once inside the function that
/// callgrind counts. Prints the number of jobs replayed.
int run_exectime_probe(const SimContext& ctx, const CommonOptions& opt, const std::string& variant);

/// One configurable run with full traces (jobs and a dense state trace).
nlohmann::json run_single(const SimContext& ctx, const CommonOptions& opt, const Scenario& scenario, Approach approach,
                          std::int32_t trace_step_us);

/// Simulated seconds per wall second of the board emulation on one core.
nlohmann::json run_benchmark(const SimContext& ctx, const CommonOptions& opt, double simulated_s);

}  // namespace oneshot::sim

namespace oneshot::sim {

struct PilOptions;

/// One scenario with the job in the emulated MCU and the same run on the host: costs,
/// and whether every actuator code and estimate is bit-identical.
nlohmann::json run_pil_compare(const SimContext& ctx, const CommonOptions& opt, const PilOptions& pil,
                               const Scenario& scenario, Approach approach);

/// Table I with the job in the emulated MCU (one QEMU for every run), beside the host.
nlohmann::json run_pil_table1(const SimContext& ctx, const CommonOptions& opt, const PilOptions& pil,
                              const std::vector<Scenario>& scenarios, std::size_t seeds);

/// Experiment 5 on an MCU: instructions per job (QEMU plugin) of half/complete ×
/// table/generic × float/fixed over the jobs of 4 s, and flash/RAM of each image.
nlohmann::json run_exectime_target(const SimContext& ctx, const CommonOptions& opt, const PilOptions& base);

/// What `oneshot-sim report` runs besides the common options.
struct ReportOptions {
  std::vector<Scenario> scenarios;  ///< Table I scenarios.
  std::size_t seeds = 20;           ///< Seeds per scenario.
  std::string self_path;            ///< This executable (for callgrind).
  std::string firmware_dir;         ///< Build tree with the firmware images (empty: this build's).
  bool mcu = true;                  ///< Include the MCU section (instruction counts, PIL).
};

/// Every experiment, Table I in the three number formats, the table, the firmware on both
/// MCUs and the product targets: writes OUTDIR/report.md and report.json.
nlohmann::json run_report(const SimContext& ctx, const CommonOptions& opt, const ReportOptions& report);

}  // namespace oneshot::sim
