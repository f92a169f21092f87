/// @file ncs_cpu_stats.hpp
/// @brief A run's figures of a node's CPU (CpuRunStats, ncs_loop.hpp) from the engine's
///        per-task statistics (the controller's or the sensor's job, ncs_cpu.hpp).
#pragma once

#include <cstddef>

#include "ncs_loop.hpp"
#include "oneshot/engine/cpu.hpp"

namespace oneshot::ncs::loop {

/// Job `task`'s statistics on `cpu` into `c` (busy time over every task, the other tasks' misses).
inline void cpu_stats(const engine::cpu::Cpu& cpu, std::size_t task, CpuRunStats& c) {
  const engine::cpu::CpuTaskStats& st = cpu.stats()[task];
  c.present = true;
  c.jobs = st.finished;
  c.response_min = st.response_min;
  c.response_max = st.response_max;
  c.response_sum_us = st.response_sum_s * 1e6;
  c.deadline_misses = st.deadline_misses;
  c.sample_min = st.sample_min;
  c.sample_max = st.sample_max;
  for (std::size_t e = 0; e < cpu.stats().size(); ++e) {
    c.busy += cpu.stats()[e].busy;
    if (e != task) c.other_misses += cpu.stats()[e].deadline_misses;
  }
}

}  // namespace oneshot::ncs::loop
