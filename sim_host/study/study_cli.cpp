/// @file study_cli.cpp
/// @brief `oneshot-sim study check FILE`, `oneshot-sim study run FILE` and `oneshot-sim study
///        report FILE OUTDIR` (with traced runs), `oneshot-sim study bench FILE` (events and
///        wall time of the sweep): study files (`oneshot-study/1`, docs/study-files.md) from the
///        command line; `merge` finishes the shards of `study run`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "ncs_loop.hpp"
#include "study_bench.hpp"
#include "study_check.hpp"
#include "study_file_report.hpp"
#include "study_file_runner.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::sim {
namespace {

/// A study file resolved into everything `study check` can compute and, when it can run, mapped
/// onto the ncs loop or onto its study's runner (study_file_runner.hpp).
struct Checked {
  nlohmann::json resolution;             ///< resolve_file_study(), plus "runnable" (and "refusal").
  std::optional<study::NcsStudy> ncs;    ///< Set when the file runs on the ncs loop.
  std::shared_ptr<const study::FileStudyRunner> other;  ///< Set when it runs on another study's runner.
  std::string refusal;                   ///< "field '<f>': <reason>" when it does not run.
};

/// Loads and resolves a study file; bad input (a parse error, a bus over 100 %, a plant that
/// cannot be designed) throws engine::InputError before anything is written. What `study run`
/// cannot run is not bad input: it is kept in `refusal`, naming the field.
Checked check_file(const std::string& path) {
  const engine::StudyFile generic = engine::load_study(path, nullptr);
  Checked c;
  c.resolution = study::resolve_file_study(generic);
  try {
    c.other = study::map_file_study(generic, path);
    if (!c.other) {
      c.ncs = generic.study != "ncs" ? study::map_ncs_study(generic)  // refuses naming 'study'
                                     : study::map_ncs_study(engine::load_study(path, &study::ncs_schema()));
    }
  } catch (const engine::InputError& e) {
    c.refusal = e.what();
    const std::string prefix = generic.source + ": ";
    if (c.refusal.rfind(prefix, 0) == 0) c.refusal.erase(0, prefix.size());
  }
  c.resolution["runnable"] = c.ncs.has_value() || c.other != nullptr;
  if (c.ncs) {
    study::add_ncs_designs(c.resolution, *c.ncs);
    study::attach_bus_bounds(*c.ncs, c.resolution);
    c.resolution["runs_with"] = "ncs";
  } else if (c.other) {
    c.other->add_design(c.resolution);
    c.resolution["runs_with"] = c.other->study();
  } else {
    c.resolution["refusal"] = c.refusal;
  }
  return c;
}

/// The options of a command as the study runners take them.
study::FileCommand file_command(const std::string& file, std::size_t seeds, unsigned threads, const std::string& out) {
  study::FileCommand f;
  f.file = file;
  f.seeds = seeds;
  f.threads = threads;
  f.out = out;
  return f;
}

struct CheckCli {
  std::string file;
  std::string json;
};

struct RunCli {
  std::string file;
  std::size_t seeds = 0;
  unsigned threads = 0;
  std::string shard = "0/1";
  std::string out = "out/study";
  std::string json;
  bool no_plots = false;
  bool analytic = false;
  double max_duration_s = 0;  ///< Every scenario's simulated time capped there (when given).
};

struct ReportCli {
  std::string file;
  std::string out;
  std::size_t seeds = 0;
  unsigned threads = 0;
  bool no_plots = false;
  double max_duration_s = 0;
  std::string trace;  ///< --trace: approaches to trace, comma-separated (empty: the default selection).
};

struct BenchCli {
  std::string file;
  std::size_t seeds = 0;
  unsigned threads = 0;
  double max_duration_s = 0;
  std::string json;
};

/// The file's ncs loop, its scenarios cut at `max_duration_s` when the option was given.
study::NcsStudy runnable(const Checked& k, const CLI::Option* max_duration, double max_duration_s) {
  if (k.other)  // the commands route a file of another study to its runner before
    throw std::logic_error("a " + std::string(k.other->study()) + " file on the ncs loop");
  if (!k.ncs) throw engine::InputError(k.resolution.at("source").get<std::string>() + ": " + k.refusal);  // one line, nothing written
  study::NcsStudy s = *k.ncs;
  if (max_duration->count() > 0) study::cap_duration(s, max_duration_s, "--max-duration");
  return s;
}

/// Each scenario's simulated time as it runs, and whether --max-duration cut it; with a stepped
/// set-point (a `reference` of steps or a file), each scenario's set-point.
std::string simulated_time_text(const study::NcsStudy& s, const CLI::Option* max_duration, double max_duration_s) {
  std::ostringstream t;
  t << "Simulated time per run:";
  for (std::size_t i = 0; i < s.scenarios.size(); ++i)
    t << (i == 0 ? " " : ", ") << s.scenarios[i].name << " " << s.scenarios[i].duration_s << " s";
  if (max_duration->count() > 0) t << " (capped by --max-duration " << max_duration_s << ")";
  t << ".";
  bool stepped = false;  // only then: the reports of square-wave files stay as they were
  for (const ncs::Scenario& x : s.scenarios) stepped = stepped || x.setpoint_changes != nullptr;
  if (stepped) {
    t << " Set-point:";
    for (std::size_t i = 0; i < s.scenarios.size(); ++i) {
      const ncs::Scenario& x = s.scenarios[i];
      t << (i == 0 ? " " : ", ") << x.name << " ";
      if (x.setpoint_changes) {
        t << x.setpoint_description;
      } else {
        t << "square +-" << x.amplitude_volts << " V, T_r " << x.period_s << " s";
      }
    }
    t << ".";
  }
  return t.str();
}

constexpr const char* kMaxDurationHelp = "cap every scenario's simulated seconds (at least one period h; default: the file's)";

void add_study_commands(CLI::App* group) {
  {
    auto c = std::make_shared<CheckCli>();
    CLI::App* cmd = group->add_subcommand(
        "check", "Validate a study file and print what it resolves to: designs, link delay/loss summaries, CAN bounds, the grid; "
        "then, if study run cannot run it, the field and the reason (non-zero exit)");
    cmd->add_option("file", c->file, "study file (oneshot-study/1)")->required();
    cmd->add_option("--json", c->json, "write the resolution as JSON to PATH, or '-' for standard output");
    cmd->callback([c]() {
      const Checked k = check_file(c->file);
      if (!c->json.empty()) util::write_json(c->json, k.resolution);
      if (c->json != "-") {
        std::cout << study::describe_resolution(k.resolution);
        if (k.other) std::cout << k.other->describe(k.resolution);
        if (k.ncs || k.other) std::cout << "runs with: oneshot-sim study run " << c->file << "\n";
      }
      if (!k.ncs && !k.other) {  // the resolution is out; the refusal is the last line, and the exit is non-zero
        std::cout.flush();
        std::cerr << "cannot run: " << k.refusal << "\n";
        throw CLI::RuntimeError(1);
      }
    });
  }
  {
    auto c = std::make_shared<RunCli>();
    CLI::App* cmd = group->add_subcommand("run", "Run a study file's approaches x scenarios x seeds (files with \"study\": \"ncs\", \"dropping\", \"sod\", \"oneshot\" or \"petc\")");
    cmd->add_option("file", c->file, "study file (oneshot-study/1)")->required();
    cmd->add_option("--seeds", c->seeds, "seeds per scenario (default: the file's seeds.count)")->check(CLI::Range(2, 10000000));
    cmd->add_option("--threads", c->threads, "worker threads (0: every core)")->capture_default_str();
    cmd->add_option("--shard", c->shard, "run part i/N and write OUT/run.shard-i-of-N.json (`oneshot-sim merge`)")->capture_default_str();
    cmd->add_option("--out", c->out, "output directory")->capture_default_str();
    cmd->add_option("--json", c->json, "write the result as JSON to PATH, or '-' for standard output");
    cmd->add_flag("--no-plots", c->no_plots, "write CSV files only (no gnuplot)");
    const CLI::Option* max_duration = cmd->add_option("--max-duration", c->max_duration_s, kMaxDurationHelp);
    cmd->add_flag("--analytic", c->analytic,
                  "also the exact expected cost over the noise for each run's timing, as `ncs table --analytic` "
                  "(analytic_mean, analytic_ci95, variance_reduction, ...; approaches whose runs leave the linear "
                  "loop: analytic_refused with the reason)");
    cmd->callback([c, max_duration]() {
      const Checked k = check_file(c->file);
      study::FileCommand f = file_command(c->file, c->seeds, c->threads, c->out);
      f.shard = c->shard;
      f.json = c->json;
      f.no_plots = c->no_plots;
      f.analytic = c->analytic;
      f.max_duration = max_duration->count() > 0;
      if (k.other) {
        k.other->run(f);
        return;
      }
      const study::NcsStudy s = runnable(k, max_duration, c->max_duration_s);
      study::run_file_sweep(
          f, [&](const engine::Shard& part) { return study::run_ncs_sweep(s, c->seeds, c->threads, part, c->analytic); },
          study::run_outputs);
    });
  }
  {
    auto c = std::make_shared<ReportCli>();
    CLI::App* cmd = group->add_subcommand(
        "report", "Run a study file as `study run` does and write OUTDIR/report.md: the resolved configuration, costs with "
                  "95 % intervals, ratios to I (an ncs file; another study's file: to its first approach), paired differences, per-link counters, the cost plot; OUTDIR/report.json");
    cmd->add_option("file", c->file, "study file (oneshot-study/1)")->required();
    cmd->add_option("outdir", c->out, "output directory")->required();
    cmd->add_option("--seeds", c->seeds, "seeds per scenario (default: the file's seeds.count)")->check(CLI::Range(2, 10000000));
    cmd->add_option("--threads", c->threads, "worker threads (0: every core)")->capture_default_str();
    const CLI::Option* max_duration = cmd->add_option("--max-duration", c->max_duration_s, kMaxDurationHelp);
    cmd->add_flag("--no-plots", c->no_plots, "no plot (no gnuplot): the cost table's and the traces' CSV files only");
    const CLI::Option* trace = cmd->add_option(
        "--trace", c->trace,
        "approaches traced on the first scenario and seed, comma-separated (default: every approach, at most 10): "
        "CSV of states, estimates, input and messages, and a plot each");
    cmd->callback([c, max_duration, trace]() {
      const Checked k = check_file(c->file);
      if (k.other) {
        study::FileCommand f = file_command(c->file, c->seeds, c->threads, c->out);
        f.no_plots = c->no_plots;
        f.max_duration = max_duration->count() > 0;
        f.trace = trace->count() > 0;
        f.trace_names = c->trace;
        k.other->report(k.resolution, f);
        return;
      }
      const study::NcsStudy s = runnable(k, max_duration, c->max_duration_s);
      if (trace->count() > 0 && c->trace.empty()) throw engine::InputError("field '--trace': an empty approach name");
      if (trace->count() > 0 && !s.loops.empty()) throw engine::InputError("field '--trace': no traces of a file with several loops (loops[])");
      const std::vector<std::size_t> traced = s.loops.empty() ? study::trace_selection(s, c->trace)  // refused before anything is written
                                                              : std::vector<std::size_t>{};
      util::make_directory(c->out);
      const engine::SweepResults r = study::run_ncs_sweep(s, c->seeds, c->threads, engine::Shard{});
      nlohmann::json j = study::run_outputs(r, c->out, !c->no_plots);
      if (!s.loops.empty()) {  // several loops: a section per loop, then the loops against each other
        nlohmann::json resolution = k.resolution;
        resolution["seeds"]["count"] = r.spec.seeds;
        std::string md;
        for (std::size_t i = 0; i < s.loops.size(); ++i) {
          const std::string name = s.loops[i].loop;
          md += (i == 0 ? "" : "\n") + std::string("# Loop ") + name + "\n\n" +
                study::report_markdown(c->file, i == 0 ? study::describe_resolution(resolution) : "(every loop: as in loop " + s.loops[0].loop + "'s section)\n",
                                       simulated_time_text(s, max_duration, c->max_duration_s), study::loop_results(r, i),
                                       j.at("loops").at(name), c->no_plots ? "" : name + "/table.png");
        }
        md += "# The loops on one bus\n\nEach loop on the shared bus against the same loop alone on it (the other loops "
              "absent), the same seeds: the cost and the observed delays of its frames; the worst-case responses count "
              "every loop's frames (study check).\n" + j.at("markdown_interference").get<std::string>() +
              "\nNo traces: `study report` traces files with one loop.\n";
        util::write_text((std::filesystem::path(c->out) / "report.md").string(), md);
        util::write_json((std::filesystem::path(c->out) / "report.json").string(), j);
        std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(c->out) / "report.md").string()
                  << "\n";
        return;
      }
      nlohmann::json traces = study::write_traces(s, traced, c->out, !c->no_plots);
      study::mark_same_cost_as_sweep(traces, r, traced);
      j["traces"] = traces;
      nlohmann::json resolution = k.resolution;  // the grid that ran: --seeds overrides the file's count
      resolution["seeds"]["count"] = r.spec.seeds;
      resolution["grid"]["runs"] = r.spec.runs();
      const std::string md = study::report_markdown(c->file, study::describe_resolution(resolution),
                                                    simulated_time_text(s, max_duration, c->max_duration_s), r, j,
                                                    c->no_plots ? "" : "table.png") +
                             study::traces_markdown(traces, r, !c->no_plots);
      util::write_text((std::filesystem::path(c->out) / "report.md").string(), md);
      util::write_json((std::filesystem::path(c->out) / "report.json").string(), j);
      std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(c->out) / "report.md").string()
                << "\n";
    });
  }
  {
    auto c = std::make_shared<BenchCli>();
    CLI::App* cmd = group->add_subcommand(
        "bench", "Time a study file's sweep as `study run` runs it and count its kernel events (queue pops): events, wall "
                 "and CPU time, events per second per thread and per CPU second (docs/study-files.md, Speed)");
    cmd->add_option("file", c->file, "study file (oneshot-study/1)")->required();
    cmd->add_option("--seeds", c->seeds, "seeds per scenario (default: the file's seeds.count)")->check(CLI::Range(2, 10000000));
    cmd->add_option("--threads", c->threads, "worker threads (0: every core)")->capture_default_str();
    const CLI::Option* max_duration = cmd->add_option("--max-duration", c->max_duration_s, kMaxDurationHelp);
    cmd->add_option("--json", c->json, "write the figures as JSON to PATH, or '-' for standard output");
    cmd->callback([c, max_duration]() {
      const Checked k = check_file(c->file);
      study::FileCommand f = file_command(c->file, c->seeds, c->threads, "");
      f.max_duration = max_duration->count() > 0;
      const nlohmann::json j = k.other ? k.other->bench(f) : study::ncs_bench(runnable(k, max_duration, c->max_duration_s), c->seeds, c->threads);
      if (!c->json.empty()) util::write_json(c->json, j);
      if (c->json != "-") std::cout << study::bench_line(c->file, j);
    });
  }
}

}  // namespace

StudyDescriptor study_files_study() {
  std::map<std::string, SweepSummarizer> finishers = {{"run", study::run_outputs}};
  for (const auto& [experiment, finish] : study::file_study_finishers()) finishers.emplace(experiment, finish);
  return {"study", "Study files (oneshot-study/1): check what a file resolves to, run it, report it (docs/study-files.md)",
          add_study_commands, std::move(finishers), std::nullopt};
}

}  // namespace oneshot::sim
