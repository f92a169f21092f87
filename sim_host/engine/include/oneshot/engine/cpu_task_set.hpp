/// @file cpu_task_set.hpp
/// @brief A CPU's task set: scheduler, periodic and sporadic tasks, interrupt handlers,
///        context-switch overhead, execution-time models and overrun policies, and the
///        strict task-file parser (`oneshot-sim kernel`, docs/kernel.md).
///
/// Time is the engine's integer ns (files give whole µs). Priorities: 1 is the highest;
/// interrupt handlers (ISRs) run above every task whatever the scheduler, among
/// themselves by their own priority (nested, preemptive).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/cpu_job_point.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine::cpu {

/// How the CPU picks among ready tasks (ISRs always come first).
enum class SchedulerKind : std::uint8_t {
  kFixedPriority,             ///< Preemptive fixed priority (OSEK / Erika FP kernel).
  kFixedPriorityNonPreemptive,  ///< A started job runs to its end (only ISRs interrupt it).
  kEdf,                       ///< Preemptive earliest deadline first (ties: priority, then index).
};

/// What happens to a job that runs late.
enum class OverrunPolicy : std::uint8_t {
  kContinue,  ///< It runs on; later releases queue behind it (counted as overruns when late).
  kSkip,      ///< A release while the previous job is unfinished is skipped (counted).
  kAbort,     ///< A job unfinished at its absolute deadline is aborted (counted).
};

/// Per-job execution time (the job's own work, without context switches).
struct ExecModel {
  /// Model kind.
  enum class Kind : std::uint8_t { kConstant, kUniform, kEmpirical, kInstructions };
  Kind kind = Kind::kConstant;     ///< Kind.
  Duration bcet{0};                ///< Best case (the smallest value the model gives).
  Duration wcet{0};                ///< Worst case (the largest).
  std::vector<Duration> values;    ///< Empirical: histogram bin values or a trace.
  std::vector<double> weights;     ///< Empirical histogram: weights (empty: a trace, used in order).
  bool whole_us = true;            ///< Uniform draws in whole µs (constant/uniform/empirical files).
  double clock_mips = 0;           ///< Instructions: instructions per µs.
  std::uint64_t instructions_min = 0;  ///< Instructions: fewest per job.
  std::uint64_t instructions_max = 0;  ///< Instructions: most per job.
  std::string source;              ///< Where the figures came from (file, variant).

  /// Execution time of job `k` (a trace is indexed by k; other draws consume `rng`).
  Duration draw(RandomStream& rng, std::uint64_t k) const;
};

/// Time of `instructions` at `mips` instructions per µs, rounded up to whole ns:
/// t = ⌈instructions · 1000 / mips⌉ ns.
Duration instruction_time(std::uint64_t instructions, double mips);

/// One task or ISR.
struct TaskSpec {
  std::string name;                ///< Unique among tasks and ISRs.
  bool sporadic = false;           ///< Sporadic: arrivals ≥ period apart (uniform up to max_interarrival).
  Duration period{0};              ///< T: period, or minimum inter-arrival time.
  Duration max_interarrival{0};    ///< Sporadic: largest gap between arrivals (≥ period).
  Duration offset{0};              ///< First arrival.
  Duration deadline{0};            ///< D, relative to the arrival.
  Duration release_jitter{0};      ///< J: a job becomes ready U[0, J] (whole µs) after its arrival.
  Duration nonpreemptive{0};       ///< The first part of each job that tasks cannot preempt.
  int priority = 1;                ///< 1 = highest (ties: earlier in the file first).
  ExecModel exec;                  ///< Execution time.
  OverrunPolicy overrun = OverrunPolicy::kContinue;  ///< Late jobs.
  JobPoint sample_at = job_start();  ///< Where the job reads its input (cpu_job_point.hpp).
  JobPoint actuate_at = job_end();   ///< Where it writes its output (not before sample_at).
  /// Released from outside (Cpu::release(): a node's job on its input's arrival), never by
  /// its own arrivals; the analysis takes it as sporadic with minimum inter-arrival `period`.
  bool external = false;
};

/// A CPU and what runs on it.
struct TaskSet {
  std::string name = "cpu";        ///< For reports.
  SchedulerKind scheduler = SchedulerKind::kFixedPriority;  ///< Task scheduler.
  Duration context_switch{0};      ///< Charged whenever a task job is dispatched after another (or idle).
  std::vector<TaskSpec> tasks;     ///< Tasks.
  std::vector<TaskSpec> isrs;      ///< Interrupt handlers (cost = exec; no overrun policy but continue).
  /// Random streams "cpu/<name>/<task>/exec|jitter|arrival" (a study file's CPUs) instead of
  /// "cpu/<task>/…" (a task file's single CPU).
  bool streams_per_cpu = false;

  /// Σ wcet/T over tasks and ISRs (context switches excluded).
  double utilization() const;
};

/// Name of a scheduler as in the task file.
const char* to_string(SchedulerKind s);
/// Name of an overrun policy as in the task file.
const char* to_string(OverrunPolicy p);

/// Parses a task file (docs/kernel.md): strict JSON, unknown and duplicate keys refused, every
/// value range-checked; InputError (json_fields.hpp) naming the field, e.g.
/// "tasks.json: field 'tasks[1].bcet_us': exceeds wcet_us". Relative trace and exectime files
/// are read from `base_dir`.
TaskSet parse_task_set(const std::string& text, const std::string& source, const std::string& base_dir);
/// Parses one execution-time model object (the task file's "exec"; `field` names it in errors).
ExecModel parse_exec_model(const nlohmann::json& j, const std::string& field, const std::string& base_dir);
/// Parses a task file's object `root` (the keys name, scheduler, context_switch_us, tasks,
/// isrs); fields named under `prefix` ("cpus[0]" → "cpus[0].tasks[1].wcet_us"; "" for a task
/// file). `allow_no_tasks`: an empty or absent "tasks" accepted (a study file's CPU whose only
/// task may be a node's job). InputError without the source.
TaskSet parse_task_set_json(const nlohmann::json& root, const std::string& prefix, const std::string& base_dir,
                            bool allow_no_tasks);
/// Parses a node's job (a study file's `nodes[i].job`) with the task parser: the task keys
/// wcet_us, bcet_us, exec, priority, deadline_us, nonpreemptive_us, overrun (no name, period,
/// offset, jitter, sample or actuation point: the node reads its input and sends at the job's
/// end, released by its input's arrival). Named `name`, external, sporadic; its period (the
/// minimum inter-arrival) and, when `deadline_us` is absent, its deadline are 0: the runner
/// sets them. InputError naming `field`.
TaskSpec parse_node_job(const nlohmann::json& j, const std::string& field, const std::string& name, const std::string& base_dir);
/// Reads (bounded) and parses a task file.
TaskSet load_task_set(const std::string& path);

/// The task set as a task file (times in µs; execution as wcet_us = ⌈wcet⌉, bcet_us = ⌊bcet⌋,
/// uniform): `kernel analyze` reads it back.
nlohmann::json task_set_json(const TaskSet& set);

}  // namespace oneshot::engine::cpu
