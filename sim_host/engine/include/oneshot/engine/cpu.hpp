/// @file cpu.hpp
/// @brief A CPU on the event kernel: releases, dispatches, preemptions and completions of
///        the jobs of a task set (cpu_task_set.hpp), with ISRs, context switches and
///        overrun policies; every scheduling event logged (compact) and counted.
///
/// Sample and actuation: the instants at which a job's own work (switches excluded) reaches
/// its task's sample_at / actuate_at offsets (cpu_job_point.hpp), found exactly when the run
/// segment that crosses them is accounted (no extra event); an offset 0 is the job's start.
/// Events: arrivals and completions in class kCompute; the dispatcher in class kBus, after
/// every other event of the instant, so simultaneous releases are arbitrated together (no
/// spurious preemption at an instant where several jobs arrive). The running job's
/// completion is an event carrying a dispatch generation; a preemption makes it stale.
/// A context switch costs `context_switch` of CPU time, charged to the incoming task job
/// whenever the CPU switches to a task job other than the last one it ran (ISRs return
/// to the interrupted job without one). Random streams per task: "cpu/<task>/exec",
/// "cpu/<task>/jitter", "cpu/<task>/arrival" ("cpu/<cpu>/<task>/…" with
/// TaskSet::streams_per_cpu). External tasks arrive only by release().
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "oneshot/engine/cpu_task_set.hpp"
#include "oneshot/engine/kernel.hpp"

namespace oneshot::engine::cpu {

/// What happened (one log entry).
enum class CpuEventKind : std::uint8_t {
  kRelease,   ///< A job became ready.
  kStart,     ///< First dispatch of a job.
  kPreempt,   ///< A running job lost the CPU.
  kResume,    ///< A preempted job got it back.
  kFinish,    ///< A job completed.
  kSkip,      ///< A release skipped (overrun policy skip).
  kAbort,     ///< A job aborted at its deadline (overrun policy abort).
  kSample,    ///< A job read its input (sample_at reached; logged when found, with its own instant).
  kActuate,   ///< A job wrote its output (actuate_at reached; likewise).
};

/// One log entry (16 bytes). Entries are in time order except kSample / kActuate, which are
/// logged when the run segment crossing them ends (not counted as scheduling events).
struct CpuLogEntry {
  std::int64_t t_ns = 0;       ///< When.
  std::uint32_t job = 0;       ///< Job index of the entity (wraps after 2^32).
  std::uint16_t entity = 0;    ///< Task index, or tasks.size() + ISR index.
  CpuEventKind kind = CpuEventKind::kRelease;  ///< What.
};

/// A finished (or aborted) job.
struct CpuJob {
  std::size_t entity = 0;      ///< Task index, or tasks.size() + ISR index.
  std::uint64_t index = 0;     ///< Job number of the entity.
  SimTime arrival{0};          ///< Nominal release (period boundary + offset, or sporadic arrival).
  SimTime ready{0};            ///< Arrival + release jitter.
  SimTime start{0};            ///< First dispatch, after its context switch: where the job's code begins.
  SimTime finish{0};           ///< Completion (or abort).
  Duration exec{0};            ///< Own execution time drawn.
  bool aborted = false;        ///< Aborted at its deadline.
  SimTime sample{-1};          ///< When its input was read (sample_at reached; −1: not reached).
  SimTime actuate{-1};         ///< When its output was written (actuate_at reached; −1: not reached).
};

/// Counters and response-time extremes of one task or ISR.
struct CpuTaskStats {
  std::uint64_t released = 0;      ///< Jobs that became ready.
  std::uint64_t started = 0;       ///< Jobs dispatched at least once.
  std::uint64_t finished = 0;      ///< Jobs completed.
  std::uint64_t deadline_misses = 0;  ///< Completed after the deadline, or aborted.
  std::uint64_t skipped = 0;       ///< Releases skipped (policy skip).
  std::uint64_t aborted = 0;       ///< Jobs aborted (policy abort).
  std::uint64_t overruns = 0;      ///< Jobs still unfinished when the next one arrived.
  std::uint64_t preemptions = 0;   ///< Times a job of this entity lost the CPU.
  Duration response_min{0};        ///< Smallest finish − arrival (0 before the first).
  Duration response_max{0};        ///< Largest.
  double response_sum_s = 0;       ///< Σ responses (for the mean).
  Duration start_min{0};           ///< Smallest start − arrival (sampling latency).
  Duration start_max{0};           ///< Largest.
  Duration busy{0};                ///< CPU time consumed (context switches included).
  Duration sample_min{0};          ///< Smallest sample − arrival (sampling latency at sample_at).
  Duration sample_max{0};          ///< Largest.
  Duration actuate_min{0};         ///< Smallest actuation − arrival (at actuate_at).
  Duration actuate_max{0};         ///< Largest.
  Duration io_min{0};              ///< Smallest actuation − sample (input-output latency).
  Duration io_max{0};              ///< Largest.
};

/// The CPU: attach to a kernel, start, run the kernel, read the statistics.
class Cpu {
 public:
  /// A CPU running `set` on `kernel` (registers its handlers; nothing scheduled yet). A task
  /// whose actuate_at may precede its sample_at is refused (InputError, cpu_job_point.hpp).
  Cpu(Kernel& kernel, TaskSet set);
  Cpu(const Cpu&) = delete;
  Cpu& operator=(const Cpu&) = delete;

  /// Schedules the first arrivals (not of external tasks); no arrival is scheduled after `end`.
  void start(SimTime end);
  /// A job of external task `task` (TaskSpec::external) arrives now: queued, released and
  /// dispatched as any arrival (execution drawn from its stream, overrun policy applied).
  void release(std::size_t task);
  /// Keeps the log (entries beyond `max_entries` are counted, not stored).
  void enable_log(std::size_t max_entries) { log_enabled_ = true; log_limit_ = max_entries; }
  /// Called for every finished or aborted job.
  void on_job(std::function<void(const CpuJob&)> f) { on_job_ = std::move(f); }
  /// Called at the instant a task job reaches its sample (kSample) or actuation (kActuate)
  /// point, with its entity and job index: while set, every dispatch schedules the running
  /// job's points not yet reached (class kCompute, before its completion at the same instant;
  /// a preemption makes them stale); a point at offset 0 is told at CpuJob::start. Without it
  /// no event is added (the runs stay as they were).
  void on_point(std::function<void(std::size_t entity, std::uint64_t index, CpuEventKind kind)> f);

  const TaskSet& task_set() const { return set_; }                  ///< The task set.
  const std::vector<CpuTaskStats>& stats() const { return stats_; }  ///< Per task, then per ISR.
  const std::vector<CpuLogEntry>& log() const { return log_; }      ///< The event log.
  std::uint64_t log_dropped() const { return log_dropped_; }        ///< Entries not stored.
  std::uint64_t scheduling_events() const { return sched_events_; }  ///< Entries logged or dropped.
  std::uint64_t context_switches() const { return context_switches_; }  ///< Switches charged.
  /// Name of entity `e` (a task, then the ISRs).
  const std::string& entity_name(std::size_t e) const;
  /// Number of entities (tasks + ISRs).
  std::size_t entities() const { return specs_.size(); }

 private:
  struct Job {
    std::uint64_t index = 0;
    SimTime arrival{0}, ready{0}, start{0};
    Duration exec{0}, remaining{0}, done{0};
    Duration sample_off{0}, act_off{0};  // own work before the sample / actuation point
    Duration own{0};                     // own work done (done without context switches)
    Duration cs_left{0};                 // context switch still to run in this dispatch
    SimTime sample{-1}, actuate{-1};
    bool started = false;
    bool sample_told = false, actuate_told = false;  // on_point called
  };
  struct Entity {
    const TaskSpec* spec = nullptr;
    bool isr = false;
    std::deque<Job> pending;  // ready or not yet ready (ready ≥ now), in arrival order
    std::uint64_t next_index = 0;
    SimTime next_arrival{0};
    RandomStream exec_rng, jitter_rng, arrival_rng;
  };

  void arrive(std::size_t e);
  void admit(std::size_t e);
  void make_ready(std::uint64_t arg);
  void complete(std::uint64_t generation);
  void abort_job(std::uint64_t arg);
  void dispatch();
  void request_dispatch(SimTime at);
  void account();
  void finish_job(std::size_t e, bool aborted);
  void record(std::size_t e, std::uint64_t job, CpuEventKind k);
  void log_point(std::size_t e, std::uint64_t job, CpuEventKind k, SimTime at);
  bool before(std::size_t a, std::size_t b) const;
  const Job* head_ready(std::size_t e) const;

  Kernel& kernel_;
  TaskSet set_;
  std::vector<const TaskSpec*> specs_;
  std::vector<Entity> ent_;
  std::vector<CpuTaskStats> stats_;
  HandlerId h_arrive_ = 0, h_ready_ = 0, h_complete_ = 0, h_abort_ = 0, h_dispatch_ = 0;
  HandlerId h_point_ = 0, h_start_point_ = 0;  // registered by on_point()
  SimTime end_{0};
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t running_ = kNone;       // entity whose head job holds the CPU
  std::size_t last_task_ = kNone;     // entity of the last task job dispatched
  std::uint64_t last_task_job_ = 0;   // its job index
  SimTime run_since_{0};
  std::uint64_t generation_ = 0;
  SimTime dispatch_at_{-1};
  std::function<void(const CpuJob&)> on_job_;
  std::function<void(std::size_t, std::uint64_t, CpuEventKind)> on_point_;
  void point(std::uint64_t arg);
  void start_point(std::uint64_t arg);
  bool log_enabled_ = false;
  std::size_t log_limit_ = 0;
  std::vector<CpuLogEntry> log_;
  std::uint64_t log_dropped_ = 0;
  std::uint64_t sched_events_ = 0;
  std::uint64_t context_switches_ = 0;
};

/// Name of a log entry kind ("release", "start", …).
const char* to_string(CpuEventKind k);

}  // namespace oneshot::engine::cpu
