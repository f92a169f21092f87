/// @file cpu_test_support.hpp
/// @brief Shared helpers of the CPU-model tests: a periodic task in whole µs and a run of a
///        task set on a fresh event kernel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine::cpu::test_support {

/// A periodic task in whole µs with constant (bcet = wcet) or uniform execution time;
/// deadline = period.
inline TaskSpec task(const std::string& name, std::int64_t period_us, std::int64_t wcet_us, std::int64_t bcet_us, int prio) {
  TaskSpec t;
  t.name = name;
  t.period = from_us(period_us);
  t.deadline = t.period;
  t.priority = prio;
  t.exec.wcet = from_us(wcet_us);
  t.exec.bcet = from_us(bcet_us);
  t.exec.kind = bcet_us == wcet_us ? ExecModel::Kind::kConstant : ExecModel::Kind::kUniform;
  return t;
}

/// A random task's period (µs, drawn from `periods`) and wcet (µs) giving it the share
/// u / n of the CPU, at least `wcet_min_us`.
struct PeriodAndWcet {
  std::int64_t period_us;  ///< T.
  std::int64_t wcet_us;    ///< C = max(wcet_min, round(u / n · T)).
};
template <std::size_t K>
PeriodAndWcet random_share(RandomStream& r, const std::int64_t (&periods)[K], double u, std::int64_t n,
                           std::int64_t wcet_min_us) {
  const std::int64_t p = periods[r.uniform_int(0, static_cast<std::int64_t>(K) - 1)];
  return {p, std::max<std::int64_t>(wcet_min_us, std::llround(u / static_cast<double>(n) * static_cast<double>(p)))};
}

/// Simulates `set` for `duration` (seed `seed`); per entity: stats of the jobs finished by
/// then (a job finishing later could miss interference from arrivals after the end).
inline std::vector<CpuTaskStats> simulate(const TaskSet& set, SimTime duration, std::uint64_t seed) {
  Kernel k(seed);
  Cpu cpu(k, set);
  cpu.start(duration);
  k.run_until(duration);
  return cpu.stats();
}

/// Analyses `set`, simulates it for `duration` (seed `seed`) and calls
/// check(stats, bound, analysis) for each task the analysis bounds that finished a job by
/// then; stops at the first fatal failure (an ASSERT in `check`). Returns how many it checked.
template <typename Check>
std::size_t check_bounded_tasks(const TaskSet& set, SimTime duration, std::uint64_t seed, Check&& check) {
  const Analysis a = analyze(set);
  const std::vector<CpuTaskStats> st = simulate(set, duration, seed);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < set.tasks.size() && !::testing::Test::HasFatalFailure(); ++i) {
    const TaskBound& b = a.tasks[i];
    if (!b.bounded || st[i].finished == 0) continue;
    ++checked;
    check(st[i], b, a);
  }
  return checked;
}

}  // namespace oneshot::engine::cpu::test_support
