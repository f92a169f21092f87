/// @file ncs_cpu.hpp
/// @brief The ncs controller's computation as a job on a modeled CPU (a study file's `cpus`):
///        the CPU's task set with the job among its background tasks, and the job's analysed
///        response-time bounds.
///
/// The job (TaskSpec::external) is released when a frame reaches the controller; the command
/// is computed and sent at its finish, so τ_c is the job's response time in the schedule
/// (engine cpu.hpp) instead of the U[1, 5] ms draw. Its analysis (cpu_analysis.hpp) takes it
/// as sporadic with minimum inter-arrival h − J (J: the spread of its input's arrival over a
/// period), so WCRT and BCRT bound every observed τ_c.
#pragma once

#include <cstddef>

#include "oneshot/engine/cpu_task_set.hpp"

namespace oneshot::ncs {

/// The controller's CPU.
struct ControllerCpu {
  engine::cpu::TaskSet set;  ///< Background tasks, ISRs and the controller's job (external).
  std::size_t task = 0;      ///< Index of the controller's job in set.tasks.
  engine::Duration wcrt{0};  ///< Its worst-case response time (from its release): τ_c's bound.
  engine::Duration bcrt{0};  ///< Its best-case response time.
};

}  // namespace oneshot::ncs
