/// @file study_bench.cpp
/// @brief `study bench`'s figures (see study_bench.hpp).
#include "study_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <thread>
#include <vector>

#include "closed_loop.hpp"
#include "ncs_loop.hpp"
#include "ncs_cache_pools.hpp"
#include "study_dropping_study.hpp"
#include "study_format.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {

nlohmann::json bench_figures(const engine::SweepResults& r, const std::string& source, unsigned threads, double wall_s,
                             double cpu_s) {
  const engine::SweepSpec& spec = r.spec;
  double events = 0;
  double simulated = 0;
  const std::size_t ev = r.metric("events");
  const std::size_t sim = r.metric("simulated_s");
  const std::size_t rs = r.metric("run_s");
  nlohmann::json per = nlohmann::json::object();  // per approach: its runs' events and their time on their thread
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    double ea = 0;
    double ta = 0;
    for (std::size_t x = 0; x < spec.scenarios.size(); ++x)
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        ea += r.at(a, x, k, ev);
        ta += r.at(a, x, k, rs);
        simulated += r.at(a, x, k, sim);
      }
    events += ea;
    per[spec.approaches[a]] = {{"events", ea}, {"run_s", ta}, {"events_per_run_s", ta > 0 ? ea / ta : 0.0}};
  }
  return {{"per_approach", per}, {"study_file", source}, {"runs", spec.runs()}, {"seeds", spec.seeds}, {"threads", threads},
          {"events", events}, {"simulated_s", simulated}, {"wall_s", wall_s}, {"cpu_s", cpu_s},
          {"events_per_s", events / wall_s}, {"events_per_s_per_thread", events / wall_s / threads},
          {"events_per_cpu_s", cpu_s > 0 ? events / cpu_s : 0.0}};
}

double mean_of(const engine::SweepResults& r, std::size_t approach, const std::string& metric) {
  const engine::SweepSpec& spec = r.spec;
  const std::size_t m = r.metric(metric);
  double sum = 0;
  for (std::size_t x = 0; x < spec.scenarios.size(); ++x)
    for (std::size_t k = 0; k < spec.seeds; ++k) sum += r.at(approach, x, k, m);
  return sum / static_cast<double>(spec.scenarios.size() * spec.seeds);
}

std::string bench_line(const std::string& file, const nlohmann::json& j) {
  char line[320];  // the figures (the file's name goes around them: any length)
  std::snprintf(line, sizeof line,
                ": %zu runs (%zu seeds) on %u threads: %.0f events, %.1f s simulated, wall %.2f s, CPU %.2f s; "
                "%.3g events/s per thread, %.3g events per CPU second\n",
                j.at("runs").get<std::size_t>(), j.at("seeds").get<std::size_t>(), j.at("threads").get<unsigned>(),
                j.at("events").get<double>(), j.at("simulated_s").get<double>(), j.at("wall_s").get<double>(),
                j.at("cpu_s").get<double>(), j.at("events_per_s_per_thread").get<double>(), j.at("events_per_cpu_s").get<double>());
  return "study bench " + file + line;
}

nlohmann::json ncs_bench(const NcsStudy& s, std::size_t seeds, unsigned threads) {
  engine::SweepSpec spec = study_sweep_spec(s, seeds, "bench");
  // Several loops: each loop's cost "<loop>/cost" (the loops of one shared run), then the run's figures.
  for (const NcsStudy& l : s.loops) spec.metrics.push_back(l.loop + "/cost");
  if (s.loops.empty()) spec.metrics.emplace_back("cost");
  std::int64_t last_offset_us = 0;  // the shared run goes on to the latest loop's end
  for (const NcsStudy& l : s.loops) last_offset_us = std::max(last_offset_us, l.clock_offset_us);
  for (const char* m : {"events", "simulated_s", "run_s"}) spec.metrics.emplace_back(m);
  spec.config = {{"study_file", s.source}};
  const unsigned used = threads == 0 ? std::max(1U, std::thread::hardware_concurrency()) : threads;
  const std::clock_t cpu0 = std::clock();
  const auto start = std::chrono::steady_clock::now();
  ncs::ShapeCachePools pool;  // as study run's sweep
  ncs::RunOptions options;
  options.caches = &pool;
  const engine::SweepResults r = engine::run_sweep(
      spec, engine::Shard{}, used,
      [&s, &options, last_offset_us](std::size_t a, std::size_t k, std::uint64_t seed) {
        const auto t0 = std::chrono::steady_clock::now();
        // Several loops: one run of them all on the shared engine (its events, every loop's cost).
        const std::vector<ncs::RunResult> x =
            s.loops.empty() ? std::vector<ncs::RunResult>{ncs::run(*s.ctx, s.approaches[a], s.scenarios[k], seed, options)}
                            : ncs::run_loops(loops_on_bus(s, k), s.approaches[a], seed, options.caches);
        const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::vector<double> v;
        for (const ncs::RunResult& l : x) v.push_back(l.cost);
        v.insert(v.end(), {static_cast<double>(x[0].events), s.scenarios[k].duration_s + 1e-6 * static_cast<double>(last_offset_us), run_s});
        return v;
      },
      "study bench");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  nlohmann::json j = bench_figures(r, s.source, used, wall, cpu);
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    // The mean cost over the approach's runs: the loop's, or per loop of a file with several.
    nlohmann::json& per = j["per_approach"][spec.approaches[a]];
    if (s.loops.empty()) per["cost_mean"] = mean_of(r, a, "cost");
    for (const NcsStudy& l : s.loops) per["loops"][l.loop]["cost_mean"] = mean_of(r, a, l.loop + "/cost");
  }
  return j;
}

nlohmann::json timed_bench(engine::SweepSpec spec, unsigned threads, const std::string& source, const BenchRunFn& run,
                           const char* label) {
  spec.metrics.clear();
  for (const char* m : {"cost", "events", "simulated_s", "run_s"}) spec.metrics.emplace_back(m);
  const unsigned used = threads == 0 ? std::max(1U, std::thread::hardware_concurrency()) : threads;
  const std::clock_t cpu0 = std::clock();
  const auto start = std::chrono::steady_clock::now();
  const engine::SweepResults r = engine::run_sweep(
      spec, engine::Shard{}, used,
      [&run](std::size_t a, std::size_t x, std::uint64_t seed) {
        const auto t0 = std::chrono::steady_clock::now();
        const BenchRun m = run(a, x, seed);
        const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return std::vector<double>{m.cost, m.events, m.simulated_s, run_s};
      },
      label);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  nlohmann::json j = bench_figures(r, source, used, wall, cpu);
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    const double mean = mean_of(r, a, "cost");
    j["per_approach"][spec.approaches[a]]["cost_mean"] = std::isfinite(mean) ? nlohmann::json(mean) : nlohmann::json(nullptr);
  }
  return j;
}

nlohmann::json dropping_bench(const DroppingStudy& s, std::size_t seeds, unsigned threads) {
  engine::SweepSpec spec = dropping_sweep_spec(s, seeds, "bench-dropping");
  spec.config = {{"study_file", s.source}};
  const double period_s = static_cast<double>(s.plant.plant.period_us) * 1e-6;
  return timed_bench(
      spec, threads, s.source,
      [&s, period_s](std::size_t a, std::size_t x, std::uint64_t seed) {
        const dropping::RunConfig& c = s.runs[a][x];
        const dropping::RunMetrics m = dropping::run_closed_loop(s.plant, c, seed);
        return BenchRun{m.cost, m.events, static_cast<double>(c.steps) * period_s};
      },
      "study bench (dropping)");
}

}  // namespace oneshot::study
