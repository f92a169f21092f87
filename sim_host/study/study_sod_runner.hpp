/// @file study_sod_runner.hpp
/// @brief A study file with "study": "sod" mapped onto the send-on-delta study's run
///        (sim_host/sod/sod_sim.hpp) and run on the engine's sweep: `study check`'s design,
///        `study run`'s runs and summary, `study report`, `study bench` (docs/study-files.md,
///        "Study sod").
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

/// A sod file resolved (study_sod_study.hpp).
struct SodStudy;

/// The schema of a sod file: approach kinds sod-held, sod-kf, msod, periodic; approach params
/// mu (msod's design bound μ > 1, default 5) and every (periodic: every n-th sample, whole,
/// default 1); scenario param amplitude (the step input, default 1). Absent approach params read
/// 0 (below every range): the mapping fills the kind's default.
const engine::StudySchema& sod_schema();

/// `file` (parsed with sod_schema()) mapped onto the sod run; engine::InputError
/// "<source>: field '<f>': <reason>" for what the run does not take (the plant's shape, the
/// nodes, a trigger, the links' delay and loss models, a parameter of another kind, ...).
std::shared_ptr<const SodStudy> map_sod_study(const engine::StudyFile& file);

/// What `study check` resolves of a sod file: study_check.hpp's resolve_study() of the file with
/// its plant file's shape only (the sod study runs open loop: no LQR design, no cost in its plant
/// file), the plant section from the plant file (designed: false, with the reason).
nlohmann::json resolve_sod_study(const engine::StudyFile& file);

/// Adds "sod" to the resolution `r`: A_d, B_d, Q_d, C, diag R, the sensors' thresholds and links,
/// the δt designs (with the file's seed count), per approach and scenario the run's settings.
void add_sod_design(nlohmann::json& r, const SodStudy& s);

/// The resolution's "sod" section as text, one fact per line.
std::string describe_sod(const nlohmann::json& r);

/// Runs the sweep (or one shard) of `s`: study "study", experiment "run-sod", the file's
/// approaches × scenarios, `seeds` replications (0: the file's count) on `threads` threads; the
/// run of approach a, scenario x, seed k is sod::simulate_run() (the same run as `oneshot-sim sod
/// table` on the same settings and seed). Metrics: cost = e1 + e2, e1, e2, e1_tail, e2_tail,
/// nees, sends1, sends2, time_sends1, time_sends2, lost1, lost2, detected1, detected2.
engine::SweepResults run_sod_sweep(const SodStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard);

/// The summary of a complete sweep (also the merge summarizer "run-sod"): per approach
/// cost_mean, cost_ci95, ratio_to_<first approach>, ratio_mean, ratio_ci95, e1_mean, e2_mean,
/// nees_mean, packets_mean; order; paired_differences; per_scenario (cost and, per approach, e1,
/// e2, e1_tail, e2_tail, nees, packets, time_rule_sends, losses, detected_losses with 95 %
/// intervals); links (per approach and link: sent, delivered, lost, time_rule_sent, detected);
/// markdown; files runs.csv in `out_dir`.
nlohmann::json sod_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// `study report` of a sod file: refuses --max-duration (given: true) and an empty or unknown
/// --trace name (`trace`: its text, null when not given), then the sweep, the summary, the cost
/// plot (`plots`), one traced run per selected approach (first scenario, first seed: the
/// sweep's run), OUT/report.md and OUT/report.json; `resolution` is `study check`'s (its seed
/// count and grid set to the run's).
void report_sod_file(const SodStudy& s, const std::string& file, nlohmann::json resolution, const std::string& out,
                     std::size_t seeds, unsigned threads, bool plots, bool max_duration, const std::string* trace);

/// `study bench` of a sod file: its sweep as `study run` runs it timed, each run's kernel events
/// counted (plant steps, samples, deliveries, estimator steps); study_bench.hpp's
/// bench_figures() plus per approach the mean cost (e1 + e2) over its runs.
nlohmann::json sod_bench(const SodStudy& s, std::size_t seeds, unsigned threads);

}  // namespace oneshot::study
