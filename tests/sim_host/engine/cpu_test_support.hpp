/// @file cpu_test_support.hpp
/// @brief Shared helpers of the CPU-model tests: a periodic task in whole µs and a run of a
///        task set on a fresh event kernel.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/engine/cpu.hpp"

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

/// Simulates `set` for `duration` (seed `seed`); per entity: stats of the jobs finished by
/// then (a job finishing later could miss interference from arrivals after the end).
inline std::vector<CpuTaskStats> simulate(const TaskSet& set, SimTime duration, std::uint64_t seed) {
  Kernel k(seed);
  Cpu cpu(k, set);
  cpu.start(duration);
  k.run_until(duration);
  return cpu.stats();
}

}  // namespace oneshot::engine::cpu::test_support
