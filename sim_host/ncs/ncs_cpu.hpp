/// @file ncs_cpu.hpp
/// @brief The ncs controller's computation as a job on a modeled CPU (a study file's `cpus`):
///        the CPU's task set with the job among its background tasks, and the job's analysed
///        response-time bounds.
///
/// The job (TaskSpec::external) is released when a frame reaches the controller; the command
/// is computed and sent at its finish, so τ_c is the job's response time in the schedule
/// (engine cpu.hpp) instead of the U[1, 5] ms draw. Its analysis (cpu_analysis.hpp) takes it
/// as sporadic with minimum inter-arrival h − J (J: the spread of its input's arrival over a
/// period), so WCRT and BCRT bound every observed τ_c. The one-shot controller's job is
/// released by its timer at kh + φ (analysed as periodic at h, offset φ).
///
/// The sensor's job (Scenario::sensor_cpu, the sampling-synchronized loops S and SK): released
/// by the sensor's timer at kh, it samples at its sample point (`sample_at`: its start) and its
/// frame leaves at its finish; the analysis's sampling latencies bound the sample's lag behind kh.
#pragma once

#include <cstddef>

#include "oneshot/engine/cpu_task_set.hpp"

namespace oneshot::ncs {

/// A node's CPU (the controller's, or the sensor's).
struct ControllerCpu {
  engine::cpu::TaskSet set;  ///< Background tasks, ISRs and the controller's job (external).
  std::size_t task = 0;      ///< Index of the controller's job in set.tasks.
  engine::Duration wcrt{0};  ///< Its worst-case response time (from its release): τ_c's bound.
  engine::Duration bcrt{0};  ///< Its best-case response time.
  engine::Duration sample_min{0};  ///< Earliest sample after its release (analysed).
  engine::Duration sample_max{0};  ///< Latest sample after its release (analysed).
};

}  // namespace oneshot::ncs
