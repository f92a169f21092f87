/// @file experiments.hpp
/// @brief Experiments E1–E6 of the dropping study (brief §6) on the engine's sweeps.
///
/// E1 `arrival`: λ(T_hold) closed form beside the γ frequency of the pipeline (network +
/// threshold buffer). E2/E3 `mare`: tr P̄(λ) and K̄(λ) on (λ_sys, 1] with λ_sys, λc and the
/// certificate's verdict. E4/E5 `closed-loop`: the loop at λ ∈ {0.3, 0.364, 0.44} through the
/// pipeline (T_hold = 1, D = −ln(λ/0.99)), with Bernoulli γ as a check and the delay-unaware
/// KF (R = 0.05, 2.5) as the baseline. E6 `hold`: T_hold = 1 … 6 at D = 1, 2.
/// Heavy tails: every metric is reported as median, 10–90 % band and mean with its 95 % CI.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dropping_plant.hpp"
#include "lambda_c.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/sweep.hpp"

namespace oneshot::dropping {

/// Options shared by the study's sweeps.
struct StudyOptions {
  std::string out_dir = "out/dropping";  ///< Output folder.
  unsigned threads = 0;                  ///< Worker threads (0: every core).
  std::uint64_t seed = 1;                ///< First seed.
  std::size_t seeds = 200;               ///< Seeds (Monte Carlo runs per cell).
  std::size_t steps = 1000;              ///< Steps per run.
  bool plots = true;                     ///< gnuplot PNGs.
  engine::Shard shard;                   ///< Part of the sweep to run.
  double loss = 0.01;                    ///< ε.
  engine::FaultSpec faults;              ///< closed-loop, hold: frame faults in every run (docs/faults.md).
};

/// E1: the sweep (or its shard file) and, for a whole sweep, the summary JSON (+ files).
nlohmann::json run_arrival(const StudyOptions& opt);
/// E1 summary from complete results (also the merge summarizer).
nlohmann::json arrival_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// E2/E3: tr P̄(λ), K̄(λ), certificate along λ; files mare_curve.csv, mare_curve.png, mare_gain.png.
nlohmann::json run_mare_curve(const DroppingPlant& plant, const StudyOptions& opt, const LambdaCOptions& lc);

/// E4/E5 closed loop (λ list, approaches buffered / buffered-bernoulli / unaware-R0.05 / unaware-R2.5).
nlohmann::json run_closed_loop_experiment(const DroppingPlant& plant, const StudyOptions& opt,
                                          const std::vector<double>& lambdas);
/// E4/E5 summary from complete results (also the merge summarizer).
nlohmann::json closed_loop_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// E6: T_hold = 1 … max_hold at the given D.
nlohmann::json run_hold(const DroppingPlant& plant, const StudyOptions& opt, int max_hold, const std::vector<double>& delays);
/// E6 summary from complete results (also the merge summarizer).
nlohmann::json hold_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// Memory of the buffered filter (double format) with T_hold slots: sizeof, bytes.
std::size_t buffered_filter_bytes(int t_hold);

}  // namespace oneshot::dropping
