/// @file kernel_experiment.cpp
/// @brief Study 000 on a modeled RTOS: the schedule's jitter and approaches A–E (see the header).
#include "kernel_experiment.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/enum_names.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {

namespace {

using namespace engine::cpu;

using util::path_in;

/// The control task's priority positions, in the order of the grid, and their names.
constexpr util::EnumName<ControlPriority> kPositions[] = {{ControlPriority::kHighest, "highest"},
                                                          {ControlPriority::kRateMonotonic, "rate_monotonic"},
                                                          {ControlPriority::kLowest, "lowest"}};

/// The other tasks: name, period (µs), share of the non-control utilization, sporadic max gap.
struct Other {
  const char* name;
  std::int64_t period_us;
  double share;
  std::int64_t max_gap_us;
};
constexpr Other kOthers[] = {{"uart_rx", 2000, 0.05, 6000}, {"comm", 5000, 0.15, 0},  {"loop_fast", 7000, 0.25, 0},
                             {"loop_mid", 13000, 0.25, 0},  {"logger", 31000, 0.15, 0}, {"diag", 97000, 0.15, 0}};

/// One configuration's control-job timings and what the schedule did to them.
struct ControlTrace {
  std::vector<JobTiming> jobs;
  double latency_max_ms = 0;   // sampling: sample − k·h
  double response_max_ms = 0;  // finish − k·h
};

ControlTrace control_trace(const TaskSet& set, std::uint64_t seed, double duration_s, std::int64_t h_us) {
  std::size_t control = 0;
  while (set.tasks.at(control).name != "control") ++control;
  engine::Kernel k(seed);
  Cpu cpu(k, set);
  ControlTrace t;
  cpu.on_job([&](const CpuJob& j) {
    if (j.entity != control) return;
    // The trace's release is the sampling latency, its execution the sample-to-actuation time.
    const auto rel = static_cast<std::int32_t>(std::llround(static_cast<double>((j.sample - j.arrival).count()) * 1e-3));
    const auto ex = static_cast<std::int32_t>(std::llround(static_cast<double>((j.actuate - j.sample).count()) * 1e-3));
    if (j.aborted || rel + ex >= h_us) throw std::logic_error("kernel: control job beyond its period (analysis said otherwise)");
    if (t.jobs.size() != j.index) throw std::logic_error("kernel: control jobs out of order");
    t.jobs.push_back(JobTiming{rel, ex});
    t.latency_max_ms = std::max(t.latency_max_ms, engine::to_seconds(j.sample - j.arrival) * 1e3);
    t.response_max_ms = std::max(t.response_max_ms, engine::to_seconds(j.finish - j.arrival) * 1e3);
  });
  const engine::SimTime end = engine::from_seconds(duration_s + 2 * static_cast<double>(h_us) * 1e-6, "duration");
  cpu.start(end);
  k.run_until(end + engine::from_us(h_us));
  return t;
}

std::string fmt(const char* f, double a, double b = 0) {
  char s[64];
  std::snprintf(s, sizeof s, f, a, b);
  return s;
}

}  // namespace

const char* to_string(ControlPriority p) { return util::enum_name(kPositions, p); }

ExecModel control_job_model(const KernelExperimentOptions& k) {
  if (k.exectime_file.empty()) {
    ExecModel m;
    m.kind = ExecModel::Kind::kUniform;
    m.bcet = engine::from_us(200);
    m.wcet = engine::from_us(600);
    m.source = "assumption: uniform 200-600 us (the study's jitter scenarios, scenario.hpp: a Kalman job on a 40-MIPS dsPIC)";
    return m;
  }
  const nlohmann::json j = {{"model", "instructions"}, {"clock_mips", k.clock_mips}, {"exectime_file", k.exectime_file},
                            {"variant", k.variant}};
  ExecModel m = parse_exec_model(j, "--exectime", "");
  m.source += ", " + std::to_string(m.instructions_min) + "-" + std::to_string(m.instructions_max) +
              " instructions per job at " + fmt("%g", k.clock_mips) + " MIPS (one instruction per cycle assumed)";
  return m;
}

TaskSet kernel_task_set(const ExecModel& job, std::int64_t period_us, double utilization, ControlPriority position,
                        const KernelExperimentOptions& k) {
  TaskSet s;
  s.name = "dspic33";
  s.scheduler = SchedulerKind::kFixedPriority;
  s.context_switch = engine::from_us(k.context_switch_us);
  TaskSpec isr;
  isr.name = "actuation_timer";
  isr.period = isr.deadline = engine::from_us(period_us);
  isr.exec.wcet = isr.exec.bcet = instruction_time(k.isr_instructions, k.clock_mips);
  s.isrs.push_back(isr);
  TaskSpec c;
  c.name = "control";
  c.period = c.deadline = engine::from_us(period_us);
  c.exec = job;
  c.sample_at = k.sample_at;
  c.actuate_at = k.actuate_at;
  const double h = static_cast<double>(c.period.count());
  const double rest = utilization - static_cast<double>(job.wcet.count()) / h - static_cast<double>(isr.exec.wcet.count()) / h;
  if (rest <= 0) throw std::invalid_argument("kernel: utilization " + fmt("%g", utilization) + " below the control job's own");
  // Rate-monotonic among the others; the control task first, at its rate-monotonic rank, or last.
  int prio = 1;
  c.priority = 0;  // not placed yet
  if (position == ControlPriority::kHighest) c.priority = prio++;
  for (const Other& o : kOthers) {
    if (position == ControlPriority::kRateMonotonic && c.priority == 0 && o.period_us > period_us) c.priority = prio++;
    TaskSpec t;
    t.name = o.name;
    t.period = t.deadline = engine::from_us(o.period_us);
    t.sporadic = o.max_gap_us > 0;
    t.max_interarrival = engine::from_us(t.sporadic ? o.max_gap_us : o.period_us);
    const std::int64_t w = std::max<std::int64_t>(2, std::llround(o.share * rest * static_cast<double>(o.period_us)));
    t.exec.kind = ExecModel::Kind::kUniform;
    t.exec.wcet = engine::from_us(w);
    t.exec.bcet = engine::from_us(w / 2);
    t.priority = prio++;
    s.tasks.push_back(t);
  }
  if (position == ControlPriority::kLowest || c.priority == 0) {
    c.priority = prio;
  }
  s.tasks.insert(s.tasks.begin(), c);
  return s;
}

nlohmann::json run_kernel_experiment(const SimContext& ctx, const CommonOptions& opt, const KernelExperimentOptions& k) {
  if (k.seeds < 2) throw std::invalid_argument("--seeds: at least 2 for confidence intervals");
  const std::int64_t h_us = ctx.plant().period_us;
  const ExecModel job = control_job_model(k);
  check_point_order(k.sample_at, k.actuate_at, job.bcet, job.wcet, "--actuate-at");
  Scenario base = uniform_scenario("kernel", 0, 0.2, 1.0, k.duration_s);
  engine::SweepSpec spec;
  spec.study = "oneshot";
  spec.experiment = "kernel";
  for (Approach a : kAllApproaches) {
    if (approach_available(ctx, a)) spec.approaches.emplace_back(1, info(a).letter);
  }
  spec.first_seed = opt.seed;
  spec.seeds = k.seeds;
  spec.metrics = {"cost", "sampling_latency_max_ms", "response_max_ms"};
  std::vector<TaskSet> sets;
  nlohmann::json configs = nlohmann::json::array(), excluded = nlohmann::json::array();
  for (const auto& [p, p_name] : kPositions) {
    for (double u : k.utilizations) {
      TaskSet s = kernel_task_set(job, h_us, u, p, k);
      const Analysis a = analyze(s);
      const TaskBound& b = a.tasks.front();
      const std::string name = fmt("U%.2f/", u) + p_name;
      nlohmann::json c = {{"name", name}, {"utilization", s.utilization()}, {"target_utilization", u},
                          {"priority", p_name}, {"control_priority", s.tasks.front().priority},
                          {"control_wcrt_us", b.bounded ? nlohmann::json(static_cast<double>(b.wcrt.count()) * 1e-3) : nlohmann::json(nullptr)},
                          {"control_bcrt_us", static_cast<double>(b.bcrt.count()) * 1e-3},
                          {"set_schedulable", a.schedulable}};
      if (!b.bounded || b.wcrt >= engine::from_us(h_us - 2)) {
        excluded.push_back(c);
        continue;
      }
      configs.push_back(c);
      spec.scenarios.push_back(name);
      sets.push_back(std::move(s));
    }
  }
  spec.config = {{"plant", ctx.plant().name}, {"period_us", h_us}, {"clock_mips", k.clock_mips},
                 {"control_job", job.source}, {"control_bcet_us", static_cast<double>(job.bcet.count()) * 1e-3},
                 {"control_wcet_us", static_cast<double>(job.wcet.count()) * 1e-3},
                 {"context_switch_us", k.context_switch_us}, {"sample_at", job_point_json(k.sample_at)},
                 {"actuate_at", job_point_json(k.actuate_at)}, {"isr_instructions", k.isr_instructions},
                 {"duration_s", k.duration_s}, {"configurations", configs}, {"excluded", excluded},
                 {"number_format", to_string(opt.format)}, {"discretizer", to_string(opt.discretizer)}};
  if (!sets.empty()) util::write_json(path_in(opt.out_dir, "kernel_tasks_example.json"), task_set_json(sets.back()));
  std::vector<Approach> approaches;
  for (const std::string& l : spec.approaches) approaches.push_back(parse_approach(l));
  const engine::SweepResults r = engine::run_sweep(
      std::move(spec), k.shard, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        const ControlTrace t = control_trace(sets[s], seed, k.duration_s, h_us);
        Scenario sc = base;
        sc.name = configs[s]["name"].get<std::string>();
        sc.jitter.kind = JitterModel::Kind::kTrace;
        sc.jitter.trace = t.jobs;
        sc.jitter.trace_path = "kernel schedule";
        const RunResult run = simulate(ctx, sc, seed, run_options(opt, approaches[a]));
        return std::vector<double>{run.cost.total(), t.latency_max_ms, t.response_max_ms};
      },
      "kernel");
  if (!k.shard.whole()) {
    const nlohmann::json j = engine::shard_to_json(r);
    util::write_json(path_in(opt.out_dir, engine::shard_file_name("kernel", k.shard)), j);
    return j;
  }
  return kernel_outputs(r, opt.out_dir, opt.plots);
}

nlohmann::json kernel_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  const engine::SweepSpec& spec = r.spec;
  const nlohmann::json& cfg = spec.config;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size();
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::size_t lat = r.metric("sampling_latency_max_ms"), resp = r.metric("response_max_ms");
  nlohmann::json j = {{"experiment", "kernel"}, {"seeds", spec.seeds}, {"seed", spec.first_seed}, {"config", cfg}};
  std::ostringstream md;
  md << "| control priority | U | control WCRT (ms) | max sampling latency (ms) | max response (ms) | J_A ± 95 % |";
  for (std::size_t a = 1; a < na; ++a) md << " " << spec.approaches[a] << "/A ± 95 % |";
  md << "\n|---|---|---|---|---|---|";
  for (std::size_t a = 1; a < na; ++a) md << "---|";
  md << "\n";
  std::vector<std::vector<double>> rows;
  nlohmann::json per = nlohmann::json::array();
  for (std::size_t s = 0; s < ns; ++s) {
    const nlohmann::json& c = cfg.at("configurations").at(s);
    double lat_max = 0, resp_max = 0;
    for (std::size_t k = 0; k < spec.seeds; ++k) {
      lat_max = std::max(lat_max, r.at(0, s, k, lat));
      resp_max = std::max(resp_max, r.at(0, s, k, resp));
    }
    std::size_t pos = 0;
    while (c.at("priority").get<std::string>() != kPositions[pos].name) ++pos;
    const double u = c.at("target_utilization").get<double>();
    md << "| " << c.at("priority").get<std::string>() << " | " << fmt("%.2f", u) << " | "
       << fmt("%.2f", c.at("control_wcrt_us").get<double>() * 1e-3) << " | " << fmt("%.2f", lat_max) << " | "
       << fmt("%.2f", resp_max) << " | " << fmt("%.5f ± %.5f", sm.per_scenario[0][s].mean, sm.per_scenario[0][s].ci95) << " |";
    std::vector<double> row = {static_cast<double>(pos), u};
    nlohmann::json e = c;
    e["sampling_latency_max_ms"] = lat_max;
    e["response_max_ms"] = resp_max;
    e["cost_A_mean"] = sm.per_scenario[0][s].mean;
    e["cost_A_ci95"] = sm.per_scenario[0][s].ci95;
    for (std::size_t a = 1; a < na; ++a) {
      const util::Summary& q = sm.per_scenario_ratio[a][s];
      md << " " << fmt("%.4f ± %.4f", q.mean, q.ci95) << " |";
      row.push_back(q.mean);
      row.push_back(q.ci95);
      e["ratio_to_A"][spec.approaches[a]] = {{"mean", q.mean}, {"ci95", q.ci95}};
    }
    md << "\n";
    rows.push_back(row);
    per.push_back(e);
  }
  j["configurations"] = per;
  // Largest utilization up to which the approach stays within 1 % of A (every grid point below
  // too), and within 1 % of its own ratio with the least schedule jitter (control task highest,
  // lowest U): the first is the brief's figure; the second separates the schedule's effect from
  // a constant gap (the one-shot model's information age).
  std::ostringstream th;
  auto largest = [&](std::size_t a, ControlPriority p, double bound) {
    nlohmann::json best = nullptr;
    for (std::size_t s = 0; s < ns; ++s) {
      const nlohmann::json& c = cfg.at("configurations").at(s);
      if (c.at("priority").get<std::string>() != to_string(p)) continue;
      if (sm.per_scenario_ratio[a][s].mean > bound) break;
      best = c.at("target_utilization");
    }
    return best;
  };
  for (const char* letter : {"B", "D"}) {
    std::size_t a = 0;
    while (a < na && spec.approaches[a] != letter) ++a;
    if (a == na || ns == 0) continue;
    const double own = sm.per_scenario_ratio[a][0].mean;  // first configuration: highest priority, lowest U
    for (const auto& [p, p_name] : kPositions) {
      const nlohmann::json vs_a = largest(a, p, 1.01), vs_own = largest(a, p, own * 1.01);
      j["largest_utilization_within_1pct"][letter][p_name] = vs_a;
      j["largest_utilization_within_1pct_of_own_least_jitter"][letter][p_name] = vs_own;
      auto text = [](const nlohmann::json& v) {
        return v.is_null() ? std::string("none of the grid") : fmt("U = %.2f", v.get<double>());
      };
      th << "| " << letter << " | " << p_name << " | " << text(vs_a) << " | " << text(vs_own) << fmt(" (%.4f)", own)
         << " |\n";
    }
  }
  std::ostringstream out;
  out << "Control job: " << cfg.at("control_job").get<std::string>() << " (" << fmt("%.1f", cfg.at("control_bcet_us").get<double>())
      << "-" << fmt("%.1f", cfg.at("control_wcet_us").get<double>()) << " us), h = " << cfg.at("period_us").get<double>() * 1e-3
      << " ms, context switch " << cfg.at("context_switch_us") << " us, timer ISR " << cfg.at("isr_instructions")
      << " instructions; samples at " << cfg.value("sample_at", nlohmann::json("start")).dump() << ", D and E actuate at "
      << cfg.value("actuate_at", nlohmann::json("end")).dump() << "; " << spec.seeds << " seeds x " << cfg.at("duration_s") << " s per cell; ratios paired per seed.\n\n"
      << md.str() << "\nLargest utilization at which the approach's mean cost ratio stays within 1 % of A, and within "
                     "1 % of its own ratio with the least schedule jitter (control task highest, lowest U), at that grid "
                     "point and every lower one:\n\n| approach | control priority | within 1 % of A | within 1 % of own "
                     "least-jitter ratio |\n|---|---|---|---|\n"
      << th.str();
  if (!cfg.at("excluded").empty()) {
    out << "\nExcluded (control WCRT not below h):";
    for (const auto& e : cfg.at("excluded")) out << " " << e.at("name").get<std::string>();
    out << "\n";
  }
  j["markdown"] = out.str();
  util::write_text(path_in(out_dir, "kernel.md"), out.str());
  std::vector<std::string> header = {"priority_index", "utilization"};
  for (std::size_t a = 1; a < na; ++a) {
    header.push_back("ratio_" + spec.approaches[a]);
    header.push_back("ci95_" + spec.approaches[a]);
  }
  util::write_csv(path_in(out_dir, "kernel.csv"), header, rows);
  j["files"] = {"kernel.md", "kernel.csv", "kernel_tasks_example.json"};
  if (plots && ns > 0) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1500, 520, 10) << "set output 'kernel.png'\n"
      << "set datafile separator ','\nset grid\nset xlabel 'CPU utilization'\nset ylabel 'cost / cost of A'\n"
      << "set key top left\nset multiplot layout 1,3\n";
    for (std::size_t p = 0; p < 3; ++p) {
      g << "set title " << util::gnuplot_quote(std::string("control task priority: ") + kPositions[p].name) << "\nplot ";
      for (std::size_t a = 1; a < na; ++a) {
        g << (a > 1 ? ", " : "") << "'kernel.csv' skip 1 using ($1==" << p << "?$2:1/0):" << 2 * a + 1 << ":" << 2 * a + 2
          << " with yerrorlines title " << util::gnuplot_quote(spec.approaches[a] + "/A");
      }
      g << "\n";
    }
    g << "unset multiplot\n";
    util::run_gnuplot(out_dir, "kernel.gp", g.str());
    j["files"].push_back("kernel.png");
  }
  return j;
}

}  // namespace oneshot::sim
