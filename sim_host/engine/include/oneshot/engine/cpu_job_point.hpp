/// @file cpu_job_point.hpp
/// @brief Where in a job's own execution an I/O point lies: the control job's sample (input
///        read, `sample_at`, default "start") and actuation (output write, `actuate_at`,
///        default "end"); docs/kernel.md.
///
/// The point is an amount of the job's own work (context switches and preemptions excluded)
/// done before it: for a job of execution e,
///     start: 0     end: e     fraction f: ⌊f·e⌋     instructions n: min(⌈n·1000/MIPS⌉ ns, e)
///     time t: min(t, e)
/// Both offset(e) and e − offset(e) are nondecreasing in e, so over e ∈ [C^b, C] the point is
/// earliest at offset(C^b) and the work after it smallest at C^b − offset(C^b).
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine::cpu {

/// A point in a job's execution.
struct JobPoint {
  /// How the point is given.
  enum class Kind : std::uint8_t { kStart, kEnd, kFraction, kInstructions, kTime };
  Kind kind = Kind::kStart;        ///< Kind.
  double fraction = 0;             ///< kFraction: f ∈ [0, 1] of the job's execution.
  std::uint64_t instructions = 0;  ///< kInstructions: instructions executed before the point.
  double clock_mips = 0;           ///< kInstructions: instructions per µs.
  Duration time{0};                ///< kTime: own execution before the point.

  /// Own work before the point in a job of execution `exec` (equations above).
  Duration offset(Duration exec) const;
};

/// The start of the job (the default sample point).
inline JobPoint job_start() { return JobPoint{}; }
/// The end of the job (the default actuation point).
inline JobPoint job_end() {
  JobPoint p;
  p.kind = JobPoint::Kind::kEnd;
  return p;
}

/// Parses `sample_at` / `actuate_at`: "start" | "end" | a fraction in [0, 1] | {"fraction": f}
/// | {"instructions": n, "clock_mips": m} (m defaults to `default_mips`, the task's
/// instruction-count model; refused when neither) | {"us": t}. InputError naming `field`.
JobPoint parse_job_point(const nlohmann::json& j, const std::string& field, double default_mips);

/// Parses the command-line form: "start", "end", "0.25" (fraction), "300us" (time),
/// "1200instr" (instructions at `mips`). InputError naming `field`.
JobPoint parse_job_point_text(const std::string& text, const std::string& field, double mips);

/// The task-file form of a point.
nlohmann::json job_point_json(const JobPoint& p);

/// Smallest actuate.offset(e) − sample.offset(e) over e ∈ {bcet, wcet, the points' own
/// breakpoints inside} (exact for start/end/time/instructions; fractions' floors may take
/// up to 2 ns more, the caller's margin).
Duration min_work_between(const JobPoint& sample, const JobPoint& actuate, Duration bcet, Duration wcet);

/// Refuses (InputError naming `field`) an actuation that may come before the sample for some
/// execution time in [bcet, wcet] (checked at bcet, wcet and the points' own breakpoints:
/// the offsets are piecewise linear between them).
void check_point_order(const JobPoint& sample, const JobPoint& actuate, Duration bcet, Duration wcet, const std::string& field);

}  // namespace oneshot::engine::cpu
