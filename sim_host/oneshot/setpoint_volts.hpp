/// @file setpoint_volts.hpp
/// @brief The set-point in volts from its ADC code (the board's sensor conversion), shared by
///        the emulated board's loop and the linear board.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"
#include "scenario.hpp"

namespace oneshot::sim {

/// Value (V) of ADC code `code` on output `o`: y_offset[o] + code · volts_per_code[o].
inline double code_volts(const design::DesignResult& d, std::size_t o, std::int32_t code) {
  return d.y_offset[o] + code * d.volts_per_code[o];
}

/// The set-point of every output (V) valid at `t`: the schedule's code on each output.
template <std::size_t P>
Vector<double, P> setpoint_volts_at(const design::DesignResult& d, const SetpointSchedule& schedule, engine::SimTime t) {
  Vector<double, P> r;
  for (std::size_t o = 0; o < P; ++o) r[o] = code_volts(d, o, schedule.code_at(t.count()));
  return r;
}

}  // namespace oneshot::sim
