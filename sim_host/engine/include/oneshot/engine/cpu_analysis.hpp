/// @file cpu_analysis.hpp
/// @brief Response-time analysis of a CPU task set (cpu_task_set.hpp): worst case
///        (Joseph–Pandya / Audsley with release jitter, blocking, ISR interference and
///        context switches; arbitrary deadlines over the level-i busy period), best case
///        (Redell–Sanfridson), sampling and actuation jitter bounds, and the EDF
///        processor-demand test. All arithmetic in integer ns.
///
/// Task i, wcet C_i, bcet C^b_i, period T_i, release jitter J_i, deadline D_i, context switch
/// cs; hp(i): the other tasks with priority ≤ p_i (equal ones counted as higher: safe);
/// lp(i): priority > p_i; ISRs k (cost C_k, period T_k, jitter J_k) interfere with every task.
///
/// Fixed priority, preemptive (Joseph & Pandya 1986; Audsley et al. 1993; Tindell et al. 1994):
///     C'_i = C_i + cs,   C'_j = C_j + 2 cs   (a preemption costs the switch in and the return)
///     B_i  = max_{j ∈ lp(i)} NP_j                        (non-preemptive first sections)
///     w(q) = B_i + (q+1) C'_i + Σ_{hp} ⌈(w + J_j)/T_j⌉ C'_j + Σ_{ISR} ⌈(w + J_k)/T_k⌉ C_k
///     R_i  = max_q w(q) − q T_i + J_i,   q = 0, 1, … while w(q) > (q+1) T_i − J_i
/// Fixed priority, non-preemptive (George et al. 1996; Davis et al. 2007, eq. of the CAN form;
/// q over the jobs of the level-i busy period t = B_i + Σ_{hep, ISR} ⌈(t + J)/T⌉ C'):
///     B_i  = max_{j ∈ lp(i)} (C_j + cs),  C'_j = C_j + cs
///     s(q) = B_i + q C'_i + Σ_{hp} (⌊(s + J_j)/T_j⌋ + 1) C'_j + Σ_{ISR} (⌊(s + J_k)/T_k⌋ + 1) C_k
///     f(q) = s_hp(q) + (q+1) C'_i + Σ_{ISR} ⌈(f + J_k)/T_k⌉ C_k,   R_i = max_q f(q) − q T_i + J_i
/// Best case (Redell & Sanfridson 2002), from R = WCRT downward to the fixed point:
///     R^b_i = C^b_i + cs + Σ_{periodic hp, ISRs} max(0, ⌈(R^b − J_j − T_j)/T_j⌉) C^b_j
///     (non-preemptive and EDF: ISRs only; sporadic entities may not arrive: none)
/// EDF (Baruah, Rosier & Howell 1990; Spuri 1996 for jitter): for every absolute deadline t
/// up to the synchronous busy period L = Σ ⌈(L + J)/T⌉ C',
///     Σ_i max(0, ⌊(t + J_i − D_i)/T_i⌋ + 1) C'_i + Σ_{ISR} ⌈(t + J_k)/T_k⌉ C_k
///       + max_{D_j > t} NP_j ≤ t,                   C'_i = C_i + 2 cs
/// EDF response time (Spuri 1996, with release jitter): the analysed job of i arrives at
/// x − J_i (released at x), every other task released at 0 after its largest jitter; only
/// jobs with absolute deadline ≤ d = x − J_i + D_i compete; B = max_{j≠i} NP_j:
///     L    = B + Σ_{all} ⌈(L + J)/T⌉ C'                       (longest busy period)
///     w(x) = B + (1 + ⌊x/T_i⌋) C'_i + Σ_{j≠i} min(⌈(w + J_j)/T_j⌉, (1 + ⌊(d + J_j − D_j)/T_j⌋)⁺) C'_j
///            + Σ_{ISR} ⌈(w + J_k)/T_k⌉ C_k,                C'_i = C_i + cs, C'_j = C_j + 2 cs
///     R_i  = max_x w(x) − x + J_i,  x ∈ [0, L) ∩ ({k T_i} ∪ {k T_j + D_j − J_j − D_i + J_i})
/// BCRT: ISRs only (as non-preemptive). Implicit deadlines without jitter, blocking or ISRs:
/// schedulable iff U ≤ 1 (Liu & Layland 1973). Jitter bounds: a point at own offset m(e)
/// (sample_at, actuate_at; cpu_job_point.hpp) lies in [cs + m(C^b), WCRT − (C^b − m(C^b))]
/// after the arrival (the start: [cs, WCRT − C^b_i]; the end: [BCRT, WCRT]).
/// A busy period longer than 10^4 of the largest period (at most 2^50 ns), or holding more than
/// 10^6 jobs of the task, is reported unbounded (the WCRT is null in the JSON).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/cpu_task_set.hpp"

namespace oneshot::engine::cpu {

/// The bounds of one task or ISR.
struct TaskBound {
  std::string name;                  ///< Task or ISR.
  bool isr = false;                  ///< An interrupt handler.
  bool bounded = true;               ///< The busy period closes (false: WCRT unbounded).
  bool schedulable = true;           ///< bounded and WCRT ≤ D.
  Duration wcrt{0};                  ///< Worst-case response time (from the arrival).
  Duration bcrt{0};                  ///< Best-case response time.
  Duration blocking{0};              ///< B_i.
  std::size_t jobs_examined = 1;     ///< q values examined in the busy period.
  Duration sampling_latency_min{0};  ///< Earliest sample after the arrival (start: cs).
  Duration sampling_latency_max{0};  ///< Latest sample (start: WCRT − C^b).
  Duration actuation_latency_min{0};  ///< Earliest actuation after the arrival (end: BCRT).
  Duration actuation_latency_max{0};  ///< Latest actuation (end: WCRT).
  Duration io_latency_min{0};        ///< Least actuation − sample (start/end: C^b).
  Duration io_latency_max{0};        ///< Largest: actuation max − sampling min.
  std::string wcrt_method;           ///< Which analysis produced wcrt.
};

/// The analysis of a task set.
struct Analysis {
  bool schedulable = true;           ///< Every task and ISR meets its deadline.
  std::string first_miss;            ///< The first task (file order) that may miss; empty if none.
  std::string reason;                ///< Why it misses (one line).
  double utilization = 0;            ///< Σ C/T (tasks and ISRs, no context switches).
  std::vector<TaskBound> tasks;      ///< Per task, in file order.
  std::vector<TaskBound> isrs;       ///< Per ISR.
  Duration edf_horizon{0};           ///< EDF: the busy period checked.
  std::size_t edf_points = 0;        ///< EDF: deadlines checked.
};

/// Analyzes `set` under its scheduler.
Analysis analyze(const TaskSet& set);

/// The analysis as JSON (`oneshot-sim kernel analyze`): {"schedulable", "tasks": [{"name",
/// "wcrt_us", "bcrt_us", "schedulable", …}], …}; an unbounded WCRT is null.
nlohmann::json analysis_json(const TaskSet& set, const Analysis& a);

}  // namespace oneshot::engine::cpu
