/// @file kernel_cli.cpp
/// @brief `oneshot-sim kernel analyze|simulate`: response-time analysis and simulation of a
///        task file on the engine's CPU model (docs/kernel.md), with the Gantt chart of the
///        first hyperperiod.
#include <algorithm>
#include <chrono>
#include <numeric>
#include <sstream>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "kernel_gantt.hpp"

namespace oneshot::sim {

namespace {

using namespace engine::cpu;

struct KernelCli {
  std::string tasks;
  std::string json;
  double duration_s = 10;
  std::uint64_t seed = 1;
  std::string out_dir = "out/kernel";
  std::string log_path;
  bool no_plots = false;
};

double us_of(engine::Duration d) { return static_cast<double>(d.count()) * 1e-3; }

}  // namespace

nlohmann::json kernel_simulate(const TaskSet& set, double duration_s, std::uint64_t seed, const KernelOutputs& out,
                               double* wall_time_s) {
  const engine::SimTime end = engine::from_seconds(duration_s, "--duration");
  engine::Kernel k(seed);
  Cpu cpu(k, set);
  const engine::Duration hyper = first_hyperperiod(set);
  cpu.enable_log(out.log_path.empty() ? std::size_t{200'000} : std::size_t{20'000'000});
  cpu.start(end);
  const auto t0 = std::chrono::steady_clock::now();
  k.run_until(end);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json j = {{"duration_s", duration_s},
                      {"seed", seed},
                      {"scheduler", to_string(set.scheduler)},
                      {"utilization", set.utilization()},
                      {"tasks", nlohmann::json::array()},
                      {"isrs", nlohmann::json::array()},
                      {"scheduling_events", cpu.scheduling_events()},
                      {"engine_events", k.events_run()},
                      {"context_switches", cpu.context_switches()}};
  engine::Duration busy{0};
  for (std::size_t e = 0; e < cpu.entities(); ++e) {
    const CpuTaskStats& s = cpu.stats()[e];
    busy += s.busy;
    nlohmann::json t = {{"name", cpu.entity_name(e)},
                        {"released", s.released},
                        {"finished", s.finished},
                        {"response_min_us", us_of(s.response_min)},
                        {"response_max_us", us_of(s.response_max)},
                        {"response_mean_us", s.finished ? s.response_sum_s * 1e6 / static_cast<double>(s.finished) : 0.0},
                        {"start_latency_min_us", us_of(s.start_min)},
                        {"start_latency_max_us", us_of(s.start_max)},
                        {"deadline_misses", s.deadline_misses},
                        {"overruns", s.overruns},
                        {"skipped", s.skipped},
                        {"aborted", s.aborted},
                        {"preemptions", s.preemptions}};
    if (e < set.tasks.size()) {
      // At the task's sample_at / actuate_at (defaults: the start, the end).
      t["sample_at"] = job_point_json(set.tasks[e].sample_at);
      t["actuate_at"] = job_point_json(set.tasks[e].actuate_at);
      t["sampling_latency_min_us"] = us_of(s.sample_min);
      t["sampling_latency_max_us"] = us_of(s.sample_max);
      t["sampling_jitter_us"] = us_of(s.sample_max - s.sample_min);
      t["actuation_latency_min_us"] = us_of(s.actuate_min);
      t["actuation_latency_max_us"] = us_of(s.actuate_max);
      t["actuation_jitter_us"] = us_of(s.actuate_max - s.actuate_min);
      t["io_latency_min_us"] = us_of(s.io_min);
      t["io_latency_max_us"] = us_of(s.io_max);
      t["io_jitter_us"] = us_of(s.io_max - s.io_min);
    }
    j[e < set.tasks.size() ? "tasks" : "isrs"].push_back(t);
  }
  j["measured_utilization"] = duration_s > 0 ? engine::to_seconds(busy) / duration_s : 0.0;
  if (wall_time_s != nullptr) *wall_time_s = wall;  // printed, never in the results
  if (!out.log_path.empty()) {
    std::ostringstream o;
    o << "t_us,task,job,event\n";
    for (const CpuLogEntry& e : cpu.log()) {
      o << static_cast<double>(e.t_ns) * 1e-3 << "," << cpu.entity_name(e.entity) << "," << e.job << "," << to_string(e.kind) << "\n";
    }
    util::write_text(out.log_path, o.str());
    j["log"] = {{"file", out.log_path}, {"entries", cpu.log().size()}, {"dropped", cpu.log_dropped()}};
  }
  if (!out.out_dir.empty()) j["gantt"] = write_gantt(cpu, hyper, out.out_dir, out.plots);
  return j;
}

namespace {

/// `analyze` and `simulate` of a task file.
void add_kernel_commands(CLI::App* group) {
  auto c = std::make_shared<KernelCli>();
  CLI::App* an = group->add_subcommand("analyze", "worst- and best-case response times, jitter bounds, schedulability");
  an->add_option("--tasks", c->tasks, "task file (JSON, docs/kernel.md)")->required();
  an->add_option("--json", c->json, "write the analysis to PATH ('-': standard output)");
  an->callback([c] {
    const TaskSet set = load_task_set(c->tasks);
    const Analysis a = analyze(set);
    const nlohmann::json j = analysis_json(set, a);
    if (!c->json.empty()) util::write_json(c->json, j);
    if (c->json != "-") {
      std::cout << (a.schedulable ? "schedulable" : "NOT schedulable: " + a.first_miss + " (" + a.reason + ")")
                << ", U = " << a.utilization << "\n";
      for (const TaskBound& b : a.tasks) {
        std::cout << "  " << b.name << ": WCRT ";
        if (b.bounded) {
          std::cout << us_of(b.wcrt) << " us";
        } else {
          std::cout << "unbounded";
        }
        std::cout << ", BCRT " << us_of(b.bcrt) << " us";
        if (b.bounded) {
          std::cout << ", response jitter <= " << us_of(b.wcrt - b.bcrt) << " us, sampling jitter <= "
                    << us_of(b.sampling_latency_max - b.sampling_latency_min) << " us, input-output latency "
                    << us_of(b.io_latency_min) << " .. " << us_of(b.io_latency_max) << " us";
        }
        std::cout << (b.schedulable ? "" : "  MISSES") << "\n";
      }
    }
  });
  CLI::App* sim = group->add_subcommand("simulate", "simulate the task set; response times, misses, Gantt of the first hyperperiod");
  sim->add_option("--tasks", c->tasks, "task file (JSON, docs/kernel.md)")->required();
  sim->add_option("--duration", c->duration_s, "simulated seconds")->required()->check(CLI::Range(1e-6, 1e5));
  sim->add_option("--seed", c->seed, "seed of the execution-time, jitter and arrival streams (default 1)");
  sim->add_option("--json", c->json, "write the result to PATH ('-': standard output)");
  sim->add_option("--out", c->out_dir, "folder of gantt.csv and gantt.png (default out/kernel)");
  sim->add_option("--log", c->log_path, "write the event log (CSV t_us,task,job,event) to PATH");
  sim->add_flag("--no-plots", c->no_plots, "no PNG (the Gantt CSV is still written)");
  sim->callback([c] {
    const TaskSet set = load_task_set(c->tasks);
    double wall = 0;
    const nlohmann::json j =
        kernel_simulate(set, c->duration_s, c->seed, KernelOutputs{c->out_dir, c->log_path, !c->no_plots}, &wall);
    if (!c->json.empty()) util::write_json(c->json, j);
    if (c->json != "-") {
      for (const auto& t : j["tasks"]) {
        std::cout << "  " << t["name"].get<std::string>() << ": response " << t["response_min_us"] << " .. "
                  << t["response_max_us"] << " us, " << t["deadline_misses"] << " deadline misses\n";
      }
      const double ev = j["scheduling_events"].get<double>();
      std::cout << ev << " scheduling events in " << wall << " s wall (" << (wall > 0 ? ev / wall : 0.0)
                << " per second, one core)\n";
    }
  });
}

}  // namespace

StudyDescriptor kernel_study() {
  return {"kernel",
          "A CPU with a real-time kernel: task sets, schedulers (fixed priority, "
          "non-preemptive, EDF), response-time analysis and simulation",
          add_kernel_commands, {}, std::nullopt};
}

}  // namespace oneshot::sim
