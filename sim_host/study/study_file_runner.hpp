/// @file study_file_runner.hpp
/// @brief The studies other than ncs that study files run ("dropping", "sod", "oneshot", "petc"):
///        one interface the `study` commands call (study_cli.cpp), one adapter per study
///        (study_file_runners.cpp) over that study's own mapping, runner and report.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

/// The options of `study run`, `study report` and `study bench` as given on the command line.
struct FileCommand {
  std::string file;              ///< The file as given.
  std::size_t seeds = 0;         ///< --seeds (0: the file's).
  unsigned threads = 0;          ///< --threads.
  std::string shard = "0/1";     ///< --shard (run).
  std::string out;               ///< --out (run) or OUTDIR (report).
  std::string json;              ///< --json (run, bench).
  bool no_plots = false;         ///< --no-plots.
  bool analytic = false;         ///< --analytic given.
  bool max_duration = false;     ///< --max-duration given.
  bool trace = false;            ///< --trace given (report).
  std::string trace_names;       ///< --trace's approaches, comma-separated (report; empty: the default selection).
};

/// A file of a study other than ncs, mapped onto that study's runs: what `study check` adds to
/// the resolution and prints, and the `run`, `report` and `bench` commands. Each refuses the
/// options it does not take (engine::InputError naming the option) before anything is written.
class FileStudyRunner {
 public:
  virtual ~FileStudyRunner() = default;
  /// The study's name ("dropping", …): the resolution's `runs_with`.
  virtual const char* study() const = 0;
  /// Adds the study's design to `study check`'s resolution.
  virtual void add_design(nlohmann::json& resolution) const = 0;
  /// The study's part of `study check`'s text (after describe_resolution()).
  virtual std::string describe(const nlohmann::json& resolution) const = 0;
  /// `study run`.
  virtual void run(const FileCommand& c) const = 0;
  /// `study report` (`resolution`: study check's).
  virtual void report(const nlohmann::json& resolution, const FileCommand& c) const = 0;
  /// `study bench`: the figures (study_bench.hpp's bench_figures() and the study's own).
  virtual nlohmann::json bench(const FileCommand& c) const = 0;
};

/// The summary of a complete sweep, its files written to `out_dir` (plots with `plots`): a
/// study's `*_run_outputs` (with "markdown" and "order_text").
using SweepOutputs = nlohmann::json (*)(const engine::SweepResults& r, const std::string& out_dir, bool plots);

/// `study run`'s common part, after the study's refusals of the options: the sweep `sweep` of
/// the part `c.shard` timed, then (the output folder made only now: a refusal from the sweep writes
/// nothing) OUT/run.shard-i-of-N.json for a part, else `outputs`' summary (printed unless `--json -`);
/// the JSON written to `--json`; the closing line printed.
void run_file_sweep(const FileCommand& c, const std::function<engine::SweepResults(const engine::Shard&)>& sweep,
                    SweepOutputs outputs);

/// `study check`'s resolution of `generic` (its study's own where it has one: sod's takes the
/// plant's shape only), with `links` always present.
nlohmann::json resolve_file_study(const engine::StudyFile& generic);

/// The runner of the file at `path` when its study (`generic.study`) has one other than ncs,
/// else nullptr; the mapping's refusals throw engine::InputError naming the field.
std::unique_ptr<const FileStudyRunner> map_file_study(const engine::StudyFile& generic, const std::string& path);

/// The merge finishers of those studies' `study run` sweeps ("run-dropping", …).
std::vector<std::pair<std::string, SweepOutputs>> file_study_finishers();

}  // namespace oneshot::study
