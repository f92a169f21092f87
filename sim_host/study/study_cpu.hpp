/// @file study_cpu.hpp
/// @brief The CPUs of a study file (`cpus`, nodes' `cpu` and `job`): each CPU's task set with
///        the node jobs among its background tasks, its response-time analysis for `study
///        check`, and the ncs controller's or sensor's job mapped onto the loop (ncs_cpu.hpp).
///
/// A node job on input arrival (an `arrival` node) is analysed as sporadic with minimum
/// inter-arrival h − J: h the plant's period, J the largest spread of its input's arrival over
/// the scenarios (the spread of its incoming links' delays, plus, when a link's sender is
/// itself woken by a link — study ncs's actuation-synchronized approaches, whose sensor samples
/// on the actuator's request — that link's spread). Its deadline defaults to h. A job on a timer
/// node is analysed as periodic at the node's period. The analysis is cpu_analysis.hpp's.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {

/// One CPU of a study file with its node jobs.
struct CpuPlan {
  engine::cpu::TaskSet set;          ///< Background tasks, then the node jobs; the ISRs.
  engine::cpu::Analysis analysis;    ///< Its response-time analysis.
  /// Per node job: (index in the file's nodes, index in set.tasks).
  std::vector<std::pair<std::size_t, std::size_t>> node_jobs;
  engine::Duration input_jitter{0};  ///< J of its arrival-driven node jobs (the largest).
};

/// The CPUs of `f` with period h = `h_us` µs: every CPU's task set and analysis.
/// engine::InputError (no source) naming the field: a node job whose input arrival has no
/// bound (`nodes[i].cpu`: a link delay without upper bound or on a CAN bus), inputs that may
/// come less than 1 µs apart (h ≤ J), a job's wcet above its minimum inter-arrival
/// (`nodes[i].job.wcet_us`), an unschedulable CPU (the task that may miss: `nodes[i].job`,
/// `cpus[c].tasks[k]` or `cpus[c].isrs[k]`), a CPU no node runs on (`cpus[c]`).
std::vector<CpuPlan> plan_cpus(const engine::StudyFile& f, std::int64_t h_us);

/// The "cpus" section of `study check`: per CPU its name, scheduler, context switch,
/// utilization, input_jitter_us, schedulable (first_miss, reason) and per task and ISR the
/// analysis (cpu_analysis.hpp analysis_json(): wcrt_us, bcrt_us, …) with "node" for node jobs
/// and, for the sensor's, "sample_lag_us" [min, max]: its sample's analysed lag behind kh.
nlohmann::json cpus_json(const engine::StudyFile& f, const std::vector<CpuPlan>& plans);

/// The cpus section as text (one line per CPU, one per task).
std::string describe_cpus(const nlohmann::json& cpus);

/// Maps the node jobs onto the ncs loop: the controller's (every scenario's controller_cpu)
/// or the sensor's (sensor_cpu: S and SK sample at its sample point, send at its finish);
/// engine::InputError (no source) naming the field for what the loop does not run: an
/// actuator's job (`nodes[i].cpu`), the sensor and the controller both on CPUs (the sensor's
/// `nodes[i].cpu`), a node on a CPU with a leg on a CAN bus (`nodes[i].cpu`), S+ with the
/// controller on a CPU (`approaches[i].kind`: it designs on the mean τ_c, which the schedule
/// gives only after the run), approaches other than I, IK, S, SK with the sensor on a CPU
/// (`approaches[i].kind`), and everything plan_cpus() refuses.
void attach_controller_cpu(const engine::StudyFile& f, NcsStudy& s);

}  // namespace oneshot::study
