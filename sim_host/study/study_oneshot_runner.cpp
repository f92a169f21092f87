/// @file study_oneshot_runner.cpp
/// @brief A "study": "oneshot" file's sweep, its summary, `study run` and `study bench` (see
///        study_oneshot_study.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/design/design_report.hpp"
#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_bench.hpp"
#include "study_oneshot_study.hpp"
#include "study_text.hpp"

namespace oneshot::study {
namespace {

const char* const kOneShotMetrics[] = {"cost", "saturated", "overruns", "faults", "jobs"};

std::string hex64(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

/// The job's timings in the CPU's schedule of `seed` over `duration_s` + 2 h: per job k,
/// release = sample − k·h rounded to whole µs, exec = (actuation − k·h rounded) − release.
std::vector<sim::JobTiming> cpu_job_trace(const OneShotFileStudy& s, std::uint64_t seed, double duration_s, std::uint64_t* events) {
  const std::int64_t h_us = s.plant.period_us;
  engine::Kernel k(seed);
  engine::cpu::Cpu cpu(k, *s.cpu);
  std::vector<sim::JobTiming> jobs;
  cpu.on_job([&](const engine::cpu::CpuJob& j) {
    if (j.entity != s.job_task) return;
    const auto rel = static_cast<std::int32_t>(std::llround(static_cast<double>((j.sample - j.arrival).count()) * 1e-3));
    // exec from the rounded response, so that release + exec is the response rounded (at most the analysed WCRT < h)
    const auto ex = static_cast<std::int32_t>(std::llround(static_cast<double>((j.actuate - j.arrival).count()) * 1e-3) - rel);
    if (j.aborted || rel + ex >= h_us) throw std::logic_error("study oneshot: the job past its period (the analysis bounds it below)");
    if (jobs.size() != j.index) throw std::logic_error("study oneshot: jobs out of order");
    jobs.push_back(sim::JobTiming{rel, ex});
  });
  const engine::SimTime end = engine::from_seconds(duration_s + 2 * static_cast<double>(h_us) * 1e-6, "duration");
  cpu.start(end);
  k.run_until(end + engine::from_us(h_us));
  if (jobs.empty()) throw std::logic_error("study oneshot: no job in the schedule");
  if (events != nullptr) *events = k.events_run();
  return jobs;
}

}  // namespace

std::shared_ptr<const OneShotFileStudy> map_oneshot_study(const engine::StudyFile& file) {
  const std::shared_ptr<OneShotFileStudy> s = map_oneshot_file(file);
  try {
    s->ctx = sim::SimContext::from_plant(s->plant);
  } catch (const std::exception& e) {  // map_oneshot_file() checked what it requires
    throw engine::InputError(file.source + ": field '" + s->plant_field + "': " + e.what());
  }
  return s;
}

sim::Scenario oneshot_run_scenario(const OneShotFileStudy& s, std::size_t x, std::uint64_t seed, std::uint64_t* cpu_events) {
  sim::Scenario c = s.scenarios.at(x);
  if (cpu_events != nullptr) *cpu_events = 0;
  if (s.cpu) c.jitter.trace = cpu_job_trace(s, seed, c.duration_s, cpu_events);
  return c;
}

engine::SweepSpec oneshot_sweep_spec(const OneShotFileStudy& s, std::size_t seeds, const char* experiment) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = experiment;
  spec.approaches = s.approaches;
  for (const sim::Scenario& x : s.scenarios) spec.scenarios.push_back(x.name);
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  nlohmann::json design;
  add_oneshot_design(design, s);
  nlohmann::json& d = design.at("oneshot");
  const nlohmann::json plant_digest = hex64(engine::stream_id(design::design_json(s.plant, s.design).dump()));
  spec.config = {{"study_file", s.source}, {"plant", s.plant.name}, {"plant_digest", plant_digest},
                 {"node", s.node}, {"approaches", d.at("approaches")}, {"scenarios", d.at("scenarios")}};
  if (d.contains("cpu")) spec.config["cpu"] = d.at("cpu");
  return spec;
}

engine::SweepResults run_oneshot_sweep(const OneShotFileStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard) {
  engine::SweepSpec spec = oneshot_sweep_spec(s, seeds, "run-oneshot");
  for (const char* m : kOneShotMetrics) spec.metrics.emplace_back(m);
  return engine::run_sweep(
      spec, shard, threads,
      [&s](std::size_t a, std::size_t x, std::uint64_t seed) {
        const sim::RunResult m = sim::simulate(*s.ctx, oneshot_run_scenario(s, x, seed), seed, s.options[a]);
        return std::vector<double>{m.cost.total(), m.saturated ? 1.0 : 0.0, static_cast<double>(m.overruns),
                                   static_cast<double>(m.faults), static_cast<double>(m.jobs)};
      },
      "study run (oneshot)");
}

nlohmann::json oneshot_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  static_cast<void>(plots);  // the table and the runs' CSV (study report draws the cost plot)
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size();
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::string ref = spec.approaches[0];
  nlohmann::json j;
  j["study"] = "oneshot";
  j["experiment"] = "study run";
  j["study_file"] = spec.config.at("study_file");
  j["plant"] = spec.config.at("plant");
  j["first_seed"] = spec.first_seed;
  j["seeds"] = spec.seeds;
  j["runs"] = spec.runs();
  j["settings"] = spec.config.at("approaches");
  j["scenario_settings"] = spec.config.at("scenarios");
  if (spec.config.contains("cpu")) j["cpu"] = spec.config.at("cpu");
  std::ostringstream md;
  md << "| approach | kind | description | mean cost J | 95 % CI | ratio to " << ref << " (95 % CI) | saturated runs | overruns |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  const std::size_t m_sat = r.metric("saturated"), m_over = r.metric("overruns"), m_faults = r.metric("faults");
  for (std::size_t a = 0; a < na; ++a) {
    const std::string& nm = spec.approaches[a];
    double saturated = 0, overruns = 0, faults = 0;
    for (std::size_t x = 0; x < ns; ++x)
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        saturated += r.at(a, x, k, m_sat);
        overruns += r.at(a, x, k, m_over);
        faults += r.at(a, x, k, m_faults);
      }
    const nlohmann::json& set = spec.config.at("approaches")[a];
    const std::string kind = set.at("kind").get<std::string>(), description = set.at("description").get<std::string>();
    j["approaches"][nm] = {{"kind", kind},
                           {"description", description},
                           {"cost_mean", finite_or_null(sm.value[a].mean)},
                           {"cost_ci95", finite_or_null(sm.value[a].ci95)},
                           {"ratio_to_" + ref, finite_or_null(sm.ratio_of_means[a])},
                           {"ratio_mean", finite_or_null(sm.ratio[a].mean)},
                           {"ratio_ci95", finite_or_null(sm.ratio[a].ci95)},
                           {"ratio_scenario_weighted", finite_or_null(sm.ratio_weighted[a].mean)},
                           {"ratio_scenario_weighted_ci95", finite_or_null(sm.ratio_weighted[a].ci95)},
                           {"saturated_runs", saturated},
                           {"overruns", overruns},
                           {"faults", faults}};
    md << "| " << nm << " | " << kind << " | " << description << " | " << md_cell(sm.value[a].mean, "%.6g") << " | ± "
       << md_cell(sm.value[a].ci95, "%.3g") << " | " << md_cell(sm.ratio_of_means[a], "%.4f") << " ± " << md_cell(sm.ratio[a].ci95, "%.4f")
       << " | " << saturated << " | " << overruns << " |\n";
  }
  engine::add_order_by_mean(j, r, sm);
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(r, sm);
  md << "\n| scenario | jitter |";
  for (std::size_t a = 0; a < na; ++a) md << " " << spec.approaches[a] << " |";
  md << "\n|---|---|";
  for (std::size_t a = 0; a < na; ++a) md << "---|";
  md << "\n";
  for (std::size_t x = 0; x < ns; ++x) {
    const nlohmann::json& sc = spec.config.at("scenarios")[x];
    nlohmann::json e = {{"name", spec.scenarios[x]}, {"jitter", sc.at("jitter")}, {"amplitude_volts", sc.at("amplitude_volts")},
                        {"change_period_s", sc.at("change_period_s")}, {"duration_s", sc.at("duration_s")}};
    md << "| " << spec.scenarios[x] << " | " << sc.at("jitter").get<std::string>() << " |";
    for (std::size_t a = 0; a < na; ++a) {
      const std::string& nm = spec.approaches[a];
      add_scenario_cost(e, sm, nm, ref, a, x);
      md << " " << md_cell(sm.per_scenario[a][x].mean, "%.6g") << " |";
    }
    md << "\n";
    j["per_scenario"].push_back(e);
  }
  j["markdown"] = md.str();
  engine::write_runs_csv(r, util::path_in(out_dir, "runs.csv"), util::NonFinite::kMissing);
  j["files"] = {"runs.csv"};
  return j;
}

nlohmann::json oneshot_bench(const OneShotFileStudy& s, std::size_t seeds, unsigned threads) {
  return timed_bench(
      oneshot_sweep_spec(s, seeds, "bench-oneshot"), threads, s.source,
      [&s](std::size_t a, std::size_t x, std::uint64_t seed) {
        std::uint64_t cpu_events = 0;  // the CPU schedule's own events (a job on a CPU), simulated for the run
        const sim::Scenario c = oneshot_run_scenario(s, x, seed, &cpu_events);
        const sim::RunResult m = sim::simulate(*s.ctx, c, seed, s.options[a]);
        return BenchRun{m.cost.total(), static_cast<double>(m.events + cpu_events), m.duration_s};
      },
      "study bench (oneshot)");
}

}  // namespace oneshot::study
