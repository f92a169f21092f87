/// @file jitter_model.hpp
/// @brief Scheduling jitter of the control job: release delay and execution time.
///
/// Period k starts at k·h. The job is released late by `release_us` (interference of
/// other tasks), samples as it starts, and runs for `exec_us`. One-shot: the job of
/// period k prepares the output applied by the timer at (k+1)·h, with τ = h − release.
/// Standard: it samples at k·h + release and writes the PWM at k·h + release + exec.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/sim/random_stream.hpp"

namespace oneshot::sim {

/// A scenario or jitter description that failed validation; what() names the field.
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Timing of one job.
struct JobTiming {
  std::int32_t release_us = 0;  ///< Delay from the period start to the sample.
  std::int32_t exec_us = 0;     ///< Execution time from the sample to the finish.
};

/// How job timings are produced.
struct JitterModel {
  /// Model kind.
  enum class Kind { kNone, kUniform, kTrace };
  Kind kind = Kind::kNone;          ///< Model kind.
  std::int32_t release_min_us = 0;  ///< Uniform: smallest release delay.
  std::int32_t release_max_us = 0;  ///< Uniform: largest release delay.
  std::int32_t exec_min_us = 0;     ///< Uniform: shortest execution.
  std::int32_t exec_max_us = 0;     ///< Uniform: longest execution.
  std::vector<JobTiming> trace;     ///< Trace: recorded timings, used cyclically.
  std::string trace_path;           ///< Trace: the file they came from.

  /// Timing of job `k` (uniform draws consume `rng`; a trace is indexed by k).
  JobTiming draw(RandomStream& rng, std::size_t k) const;
  /// Largest release + execution the model can produce (µs).
  std::int32_t max_busy_us() const;
  /// One-line description.
  std::string describe() const;
};

/// Loads the trace file a scenario names (load_jitter_trace unless a test or fuzzer gives another).
using TraceLoader = std::function<std::vector<JobTiming>(const std::string& path)>;

/// Parses {"model": "none"|"uniform"|"trace", ...}; `field` names it in errors. A relative
/// trace file is found from `base_dir` and read by `load_trace` (default: load_jitter_trace).
JitterModel parse_jitter(const nlohmann::json& j, const std::string& field, const std::string& base_dir,
                         const TraceLoader& load_trace = {});

/// Largest release delay or execution time in a scenario or trace (µs): one minute.
inline constexpr std::int64_t kMaxJobTimeUs = 60'000'000;

/// Parses trace text: the header line "release_us,exec_us", then one job per line as two
/// integers in [0, kMaxJobTimeUs] separated by a comma (spaces around them allowed; empty
/// lines and lines starting with '#' skipped). Anything else on a line is refused with the
/// line number; `source` names the text in errors (ScenarioError).
std::vector<JobTiming> parse_jitter_trace(const std::string& text, const std::string& source);

/// Reads and parses a trace CSV (bounded read; ScenarioError naming the file).
std::vector<JobTiming> load_jitter_trace(const std::string& path);

}  // namespace oneshot::sim
