/// @file board_events.hpp
/// @brief The events every board loop starts with (the emulated board's and the linear
///        board's): the same kernel events give both the same timing draws.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "oneshot/engine/kernel.hpp"
#include "scenario.hpp"

namespace oneshot::sim {

/// The whole periods h of a run and the instant the last one ends.
struct BoardPeriods {
  std::int64_t count = 0;     ///< Whole periods h in the run's duration (rounded down).
  engine::SimTime end{0};     ///< count·h: the end of the last whole period, where the run ends.
};

/// The periods of a board run of `duration_s` seconds at period `h` (the emulated board's and
/// the linear board's: the same count and end for both).
inline BoardPeriods board_periods(double duration_s, engine::Duration h) {
  const auto count = static_cast<std::int64_t>(std::floor(duration_s * 1e9 / static_cast<double>(h.count())));
  return BoardPeriods{count, engine::SimTime{count * h.count()}};
}

/// Schedules the set-point changes of `schedule` up to `end` (handler `on_setpoint`, argument
/// the change's index), the first period at 0 when `periods` > 0 (`on_period`, argument 0) and
/// the end (`on_end`), then runs `kernel` until `end`.
inline void run_board_events(engine::Kernel& kernel, const SetpointSchedule& schedule, engine::SimTime end,
                             std::int64_t periods, engine::HandlerId on_period, engine::HandlerId on_setpoint,
                             engine::HandlerId on_end) {
  using engine::EventClass;
  for (std::size_t i = 1; i < schedule.at_ns.size(); ++i) {
    if (schedule.at_ns[i] <= end.count()) kernel.schedule(engine::SimTime{schedule.at_ns[i]}, EventClass::kEnvironment, on_setpoint, i);
  }
  if (periods > 0) kernel.schedule(engine::SimTime{0}, EventClass::kActuation, on_period, 0);
  kernel.schedule(end, EventClass::kEnd, on_end);
  kernel.run_until(end);
}

}  // namespace oneshot::sim
