/// @file sod_experiments.hpp
/// @brief Experiments E1–E4 of the send-on-delta study (brief §6) as engine sweeps.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/sweep.hpp"
#include "sod_design.hpp"
#include "sod_model.hpp"
#include "sod_sim.hpp"

namespace oneshot::sod {

/// Options shared by the study's commands.
struct StudyOptions {
  std::string plant_path;                           ///< Plant file (default: the study's).
  std::size_t seeds = 100;                          ///< Monte Carlo runs per cell.
  std::uint64_t seed = 1;                           ///< First seed.
  unsigned threads = 0;                             ///< 0: every core.
  std::string out_dir = "out/sod";                  ///< Files.
  bool plots = true;                                ///< PNG plots (gnuplot).
  double delta_y = 0.5;                             ///< δy of both nodes.
  double mu = 5;                                    ///< Design bound μ.
  double amplitude = 1;                             ///< Step input amplitude.
  std::int64_t steps = 5000;                        ///< N (T = the plant's period).
  std::vector<double> losses = {0, 0.05, 0.1, 0.2}; ///< ξ of the table.
  std::vector<double> design_losses = {0.05, 0.1, 0.15, 0.2};  ///< ξ of the design command.
  engine::Shard shard;                              ///< Part of the table sweep.
  engine::FaultSpec faults;                         ///< Table: frame faults in every run (docs/faults.md).
};

/// ΔT_i (E1): mean time between packets of lossless plain SOD, per seed N·T/sends_i.
struct MeanGap {
  double mean_s[kNodes] = {};   ///< Mean over seeds.
  double ci95_s[kNodes] = {};   ///< 95 % half-width.
  double sends[kNodes] = {};    ///< Mean packets per run.
};

/// Measures ΔT at `delta_y` over opt.seeds seeds.
MeanGap measure_mean_gap(const SodModel& model, const StudyOptions& opt, double delta_y);

/// Δt* of both nodes at threshold `delta_y` and loss rate `loss`: the design inputs from
/// the measured mean gaps `g` and the options' bound μ.
DeltaTDesign design_at(const SodModel& model, const StudyOptions& opt, const MeanGap& g, double delta_y, double loss);

/// E1: ΔT for each δy.
nlohmann::json run_mean_gap(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ys);
/// `design`: P0, δt* per node and ξ, the active constraint, δt*·ξ.
nlohmann::json run_design(const SodModel& model, const StudyOptions& opt);
/// E3 a–c: the table (a sweep; with a shard, the shard file's JSON).
nlohmann::json run_table(const SodModel& model, const StudyOptions& opt);
/// The table's JSON and files from a complete sweep (also the merge summarizer).
nlohmann::json table_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots);
/// E3 d: error against packets, δt swept, beside a periodic sender with the same budget.
nlohmann::json run_curve(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ts,
                         const std::vector<double>& losses);
/// E2: δt* over δy × ξ.
nlohmann::json run_grid(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ys,
                        const std::vector<double>& losses);
/// E4: mean squared error over time of (a) and (c) at ξ, and one run's y1 with its (2b) sends.
nlohmann::json run_traces(const SodModel& model, const StudyOptions& opt, double loss);

/// Writes `j` to `path` ('-': standard output; empty: nothing).
void emit_json(const nlohmann::json& j, const std::string& path);

}  // namespace oneshot::sod
