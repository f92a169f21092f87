/// @file sim_time.hpp
/// @brief Simulated time: integer nanoseconds since the start of a run (64 bits, ±292 years).
///
/// The engine never accumulates time in floating point: every instant is an exact count of
/// nanoseconds (std::chrono::nanoseconds, whose arithmetic is integer), so events that
/// should coincide do coincide and a run is the same on every host. Nodes see time as the
/// wrapping µs counter of their own clock (time_us.hpp): node_instant() converts, with
/// the node's clock offset.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "oneshot/time_us.hpp"

namespace oneshot::engine {

/// A span of simulated time (integer ns).
using Duration = std::chrono::nanoseconds;
/// An instant of simulated time: the duration since the start of the run.
using SimTime = Duration;

/// Largest simulated instant the engine accepts (about 106 days: a margin of 2^10 below
/// the int64 limit, so sums of two instants and a delay never overflow).
inline constexpr SimTime kMaxSimTime{std::int64_t{1} << 53};

/// t in seconds (for reports and plots; never for event arithmetic).
inline double to_seconds(Duration t) { return static_cast<double>(t.count()) * 1e-9; }

/// Nanoseconds of `seconds`, rounded to the nearest ns; std::invalid_argument naming
/// `what` when it is not finite, negative, or beyond kMaxSimTime.
inline Duration from_seconds(double seconds, const std::string& what) {
  if (!std::isfinite(seconds) || seconds < 0 || seconds * 1e9 > static_cast<double>(kMaxSimTime.count())) {
    throw std::invalid_argument(what + ": must be a finite time in [0, " +
                                std::to_string(to_seconds(kMaxSimTime)) + "] s");
  }
  return Duration{std::llround(seconds * 1e9)};
}

/// Microseconds as a Duration.
constexpr Duration from_us(std::int64_t us) { return Duration{us * 1000}; }

/// The node clock's wrapping µs instant at simulated time t, for a clock that reads
/// t + offset (floor to whole µs, then modulo 2^bits of Rep).
template <typename Rep>
InstantUs<Rep> node_instant(SimTime t, Duration clock_offset = Duration{0}) {
  const std::int64_t ns = (t + clock_offset).count();
  const std::int64_t us = ns >= 0 ? ns / 1000 : -((-ns + 999) / 1000);  // floor division
  return InstantUs<Rep>(static_cast<Rep>(static_cast<std::uint64_t>(us)));
}

}  // namespace oneshot::engine
