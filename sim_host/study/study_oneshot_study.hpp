/// @file study_oneshot_study.hpp
/// @brief A "study": "oneshot" file resolved (study_oneshot_map.cpp): the reference board's loop
///        of Table I (sim_host/oneshot/: one MCU samples, estimates and actuates) with its plant,
///        per approach A–E the run's options, per scenario the set-point and the control job's
///        timing (a jitter model, or the schedule of the job on a modeled CPU); what the runner,
///        the report and the bench of such a file share (docs/study-files.md, "Study oneshot").
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/cpu_task_set.hpp"
#include "oneshot/engine/sweep.hpp"
#include "simulation.hpp"

namespace oneshot::engine {
struct StudyFile;
struct StudySchema;
struct Shard;
}  // namespace oneshot::engine

namespace oneshot::study {

/// A oneshot file resolved (map_oneshot_study()).
struct OneShotFileStudy {
  std::string source;                                ///< The study file.
  std::string plant_path;                            ///< Its plant file (resolved).
  std::string plant_field;                           ///< Where the file gives it: "plant.file" or "plant.continuous".
  design::PlantDescription plant;                    ///< The plant.
  design::DesignResult design;                       ///< Its design (design::synthesize()).
  /// Plant, design and tables of the simulator (SimContext::from_plant(plant); null from
  /// map_oneshot_file()).
  std::shared_ptr<const sim::SimContext> ctx;
  std::string node;                                  ///< The board node's name.
  std::vector<std::string> approaches;               ///< Names, in the file's order.
  std::vector<std::string> kinds;                    ///< Their kinds (the letters A–E).
  std::vector<sim::RunOptions> options;              ///< Per approach: the run's options.
  std::vector<nlohmann::json> settings;              ///< Per approach: name, kind, description, jitter and option words.
  std::vector<sim::Scenario> scenarios;              ///< Per scenario: set-point, duration, jitter model.
  /// Set when the node's job runs on a CPU (`nodes[0].cpu`): the file's CPU with the job added as
  /// the periodic task `node` (period h, arrival k·h); its schedule gives every scenario's timing.
  std::optional<engine::cpu::TaskSet> cpu;
  std::size_t job_task = 0;                          ///< The job's index in cpu->tasks.
  std::uint64_t first_seed = 1;                      ///< First seed.
  std::size_t seeds = 0;                             ///< The file's count.
};

/// The schema of a oneshot file: approach kinds A, B, C, D, E (Table I); approach word params
/// number_format (float, double), discretizer (table, nearest, generic), noise_model (exact,
/// constant), pwm_update (immediate, period); scenario params amplitude_volts, change_period_s,
/// release_min_us, release_max_us, exec_min_us, exec_max_us.
const engine::StudySchema& oneshot_schema();

/// `file` (parsed with oneshot_schema()) mapped onto the one-shot board loop; engine::InputError
/// "<source>: field '<f>': <reason>" for what the loop does not run (another plant form, nodes
/// other than one timer node at the plant's period, links, buses, a reference signal, a job that
/// may not finish within its period, ...).
/// Without the simulator's context (`ctx` null; study_oneshot_map.cpp links the design, the
/// engine and the scenario code only: the study fuzz harness reaches it).
std::shared_ptr<OneShotFileStudy> map_oneshot_file(const engine::StudyFile& file);

/// map_oneshot_file() with the simulator's context of its plant (SimContext::from_plant()).
std::shared_ptr<const OneShotFileStudy> map_oneshot_study(const engine::StudyFile& file);

/// Adds "oneshot" to the resolution `r`: the plant and its design (K, Kalman gain, ...), per
/// approach its options, per scenario the set-point and the jitter (the model, the range of
/// τ = h − release the one-shot approaches use), the CPU's analysis of the job when it has one.
void add_oneshot_design(nlohmann::json& r, const OneShotFileStudy& s);

/// The resolution's "oneshot" section as text, one fact per line.
std::string describe_oneshot(const nlohmann::json& r);

/// Scenario `x` of `s` as run with `seed`: the file's scenario, or with a CPU its timing the
/// trace of the job in the CPU's schedule for that seed (release = sample − k·h, exec = actuation
/// − sample, in whole µs); `cpu_events` (optional) set to the events of that schedule's
/// simulation (0 without a CPU).
sim::Scenario oneshot_run_scenario(const OneShotFileStudy& s, std::size_t x, std::uint64_t seed, std::uint64_t* cpu_events = nullptr);

/// The sweep of `s` for `experiment` ("run-oneshot", "bench-oneshot"): its approaches,
/// scenarios, first seed and `seeds` seeds (0: the file's count), its configuration (what a
/// shard must agree on); metrics the caller's.
engine::SweepSpec oneshot_sweep_spec(const OneShotFileStudy& s, std::size_t seeds, const char* experiment);

/// Runs the sweep (or one shard) of `s`: study "study", experiment "run-oneshot"; the run of
/// approach a, scenario x, seed k is sim::simulate() (the run of `oneshot-sim oneshot table1` on
/// the same scenario, options and seed). Metrics: cost, saturated, overruns, faults, jobs.
engine::SweepResults run_oneshot_sweep(const OneShotFileStudy& s, std::size_t seeds, unsigned threads,
                                       const engine::Shard& shard);

/// The summary of a complete sweep (also the merge summarizer): per approach kind,
/// description, cost_mean, cost_ci95, ratio_to_<first approach>, ratio_mean, ratio_ci95,
/// saturated_runs, overruns, faults; order; paired_differences; per_scenario; markdown; runs.csv
/// in `out_dir`.
nlohmann::json oneshot_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// `study report` of a oneshot file: its sweep, the summary, the cost plot (table_summary.csv,
/// table.png), OUT/report.md (`resolution_text`: what `study check` prints) and OUT/report.json.
/// No traced runs.
void oneshot_report_command(const OneShotFileStudy& s, const std::string& file, const std::string& resolution_text,
                            std::size_t seeds, unsigned threads, const std::string& out, bool plots);

/// `study bench` of a oneshot file: events and wall time of its sweep (study_bench.hpp's
/// figures), per approach the mean cost.
nlohmann::json oneshot_bench(const OneShotFileStudy& s, std::size_t seeds, unsigned threads);

}  // namespace oneshot::study
