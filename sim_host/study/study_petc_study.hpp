/// @file study_petc_study.hpp
/// @brief A "study": "petc" file (docs/study-files.md, "Study petc"): the schema, the mapping
///        onto the petc study's closed loop (sim_host/petc/petc_sim.hpp: the HDD plant, the
///        sensor's and the controller's MTM triggers, NUMRE, the MRCI, zero-delay links), the
///        design `study check` prints, `study run`'s sweep and summary, `study report`,
///        `study bench` (study_petc_map.cpp, study_petc_runner.cpp, study_petc_report.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "petc_sim.hpp"
#include "study_file_runner.hpp"

namespace oneshot::engine {
struct StudyFile;
struct StudySchema;
}  // namespace oneshot::engine

namespace oneshot::study {

/// A petc file resolved (map_petc_study()).
struct PetcStudy {
  std::string source;                                     ///< The study file.
  std::string plant_path;                                 ///< Its plant file (resolved).
  std::string sc, ca;                                     ///< The file's names of the two links.
  std::vector<std::string> approaches;                    ///< Names, in the file's order.
  std::vector<std::string> kinds;                         ///< Their kinds.
  std::vector<std::string> scenarios;                     ///< Names.
  std::vector<sim::petc::PetcSetup> setups;               ///< [scenario] the design the runs share.
  std::vector<std::vector<sim::petc::CaseSpec>> runs;     ///< [approach][scenario] the case that runs.
  std::uint64_t first_seed = 1;                           ///< First seed.
  std::size_t seeds = 0;                                  ///< The file's count.
};

/// The schema of a petc file: approach kinds tts, hold, numre-augmented, numre-dob, numre-eso;
/// approach params sigma_s, delta_s, sigma_c, delta_c (the MTM thresholds, ≥ 0; absent: the
/// nodes' triggers') and noise (0 or 1; absent: 1); scenario params noise (0 or 1, default 1),
/// sigma_w, sigma_v (≥ 0; absent: the plant file's), ratio (MRCI m, 1 … 16, default 2),
/// dob_cutoff_hz (default 1000), sample_at_update, frozen_noise (0 or 1, default 0).
const engine::StudySchema& petc_schema();

/// `file` (parsed with petc_schema()) mapped onto the petc loop; engine::InputError
/// "<source>: field '<f>': <reason>" for what the loop does not run.
std::shared_ptr<const PetcStudy> map_petc_study(const engine::StudyFile& file);

/// The case of a run as JSON (controller, observer, noise, thresholds).
nlohmann::json petc_case_json(const sim::petc::CaseSpec& c);

/// Adds "petc" to the resolution `r`: per scenario the design (plant facts, MRCI split, DOB,
/// options: setup_config), per approach its case per scenario.
void add_petc_design(nlohmann::json& r, const PetcStudy& s);

/// The resolution's "petc" section as text.
std::string describe_petc(const nlohmann::json& r);

/// The index of "GPI" (the cost of a petc file's runs) in sim::petc::metric_names().
std::size_t petc_gpi_index();

/// The sweep spec of `s` for `experiment` ("run-petc", "bench-petc"): approaches, scenarios,
/// first seed, `seeds` seeds (0: the file's count); metrics and config the caller's.
engine::SweepSpec petc_sweep_spec(const PetcStudy& s, std::size_t seeds, const char* experiment);

/// Runs the sweep (or one shard) of `s`: study "study", experiment "run-petc"; the run of
/// approach a, scenario x, seed k is sim::petc::run_case(setups[x], runs[a][x], k) (the same
/// run as `petc table`'s case on the same seed). Metrics: cost (= GPI), then
/// sim::petc::metric_names().
engine::SweepResults run_petc_sweep(const PetcStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard);

/// The summary of a complete sweep (also the merge summarizer "run-petc"): per approach
/// cost_mean (GPI), cost_ci95, ratio_to_<first>, ratio_mean, ratio_ci95 and `metrics` (every
/// metric's mean and 95 % interval over seeds of the scenario mean, as `petc table`'s
/// cases[].metrics); paired_differences, order, per_scenario, links (per approach: sent,
/// delivered per link), markdown; runs.csv in `out_dir`.
nlohmann::json petc_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// `study bench` of a petc file: its sweep timed, each run's kernel events counted;
/// bench_figures() plus per approach cost_mean (GPI).
nlohmann::json petc_bench(const PetcStudy& s, std::size_t seeds, unsigned threads);

/// Writes OUT_DIR/table_summary.csv (approach_index, mean, ci95, ratio_mean, ratio_ci95 of the
/// GPI) and, with `plots`, OUT_DIR/table.png (bars with 95 % intervals). Returns the files.
nlohmann::json write_petc_cost_plot(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// One traced run per approach of `selected` on the first scenario and the first seed: the
/// sweep's run (sim::petc::run_case with a RunTrace, which only records).
/// OUT_DIR/trace_<i>_<A>.csv (k, t_s, r, y, y_meas, u, d, d_hat, sensor_sent, actuator_sent
/// every period) and, with `plots`, trace_<i>_<A>.png (output, samples and r with the sensor's
/// sends; u with the controller's sends; d and d̂). `<i>` the approach's index from 1, `<A>`
/// its name with every character outside [A-Za-z0-9._-] as '_'. Returns per approach its
/// files, scenario, seed and the run's cost (GPI).
nlohmann::json write_petc_traces(const PetcStudy& s, const std::vector<std::size_t>& selected, const std::string& out_dir,
                                 bool plots);

/// The report of a complete sweep: the file and grid, `resolution_text`, the table of
/// petc_run_outputs() (`outputs`), per approach the petc table's columns, order, paired
/// differences, links, the plot `plot_path` (empty: none), the traces `traces`
/// (write_petc_traces(), with same_cost_as_sweep).
std::string petc_report_markdown(const PetcStudy& s, const std::string& file, const std::string& resolution_text,
                                 const engine::SweepResults& r, const nlohmann::json& outputs, const std::string& plot_path,
                                 const nlohmann::json& traces, bool plots);

/// What the `study` commands hand a petc file (study_cli.cpp's options).
using PetcCommand = FileCommand;

/// `study report` of a petc file: the sweep, OUT/runs.csv, table_summary.csv, table.png, the
/// traces, report.md, report.json; `resolution` is study check's (the report prints it with the
/// seed count and runs that ran). --max-duration and a bad --trace refused before anything is
/// written.
void petc_report_command(const PetcStudy& s, const nlohmann::json& resolution, const PetcCommand& c);

}  // namespace oneshot::study
