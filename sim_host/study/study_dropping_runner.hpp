/// @file study_dropping_runner.hpp
/// @brief A study file with "study": "dropping" mapped onto the dropping study's closed loop
///        (sim_host/dropping/closed_loop.hpp) and run on the engine's sweep: `study check`'s
///        design, `study run`'s runs and summary (docs/study-files.md, "Study dropping").
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace oneshot::engine {
struct StudyFile;
struct StudySchema;
struct SweepResults;
struct Shard;
}  // namespace oneshot::engine

namespace oneshot::study {

/// A dropping file resolved: its plant and design, per approach and scenario the run's settings
/// (study_dropping_runner.cpp).
struct DroppingStudy;

/// The schema of a dropping file: approach kinds buffered, unaware, bernoulli; approach params
/// t_hold (1 … 8, whole), r (the unaware KF's R), lambda (the Bernoulli channel's λ); scenario
/// param lambda. Absent params read 0 (below every range): the mapping fills the kind's default.
const engine::StudySchema& dropping_schema();

/// `file` (parsed with dropping_schema()) mapped onto the closed loop; engine::InputError
/// "<source>: field '<f>': <reason>" for what the loop does not run (the plant's shape, the
/// nodes, the link and its delay model, a parameter of another kind, the reference, ...).
std::shared_ptr<const DroppingStudy> map_dropping_study(const engine::StudyFile& file);

/// Adds "dropping" to the resolution `r`: L, ρ(Φ), λ_sys, the bracket of λ_c (the MARE's
/// critical arrival probability), per approach its estimator and settings, per scenario the
/// steps and the link's delay and loss.
void add_dropping_design(nlohmann::json& r, const DroppingStudy& s);

/// The resolution's "dropping" section as text, one fact per line.
std::string describe_dropping(const nlohmann::json& r);

/// Runs the sweep (or one shard) of `s`: study "study", experiment "run-dropping", the file's
/// approaches × scenarios, `seeds` replications (0: the file's count) on `threads` threads; the
/// run of approach a, scenario s, seed k is dropping::run_closed_loop() (its seed k: the same
/// runs as `dropping closed-loop` on the same settings). Metrics: cost, err, trace_p, gamma,
/// failed, the link's sent, lost, late, refused.
engine::SweepResults run_dropping_sweep(const DroppingStudy& s, std::size_t seeds, unsigned threads,
                                        const engine::Shard& shard);

/// The summary of a complete sweep (also the merge summarizer): per approach cost_mean,
/// cost_ci95, ratio_to_<first approach>, ratio_mean, ratio_ci95, err_mean, trace_p_mean,
/// gamma_mean, failed_runs; paired_differences; per_scenario; links (per approach: sent,
/// delivered, lost, late, refused); markdown; files runs.csv in `out_dir`.
nlohmann::json dropping_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

}  // namespace oneshot::study
