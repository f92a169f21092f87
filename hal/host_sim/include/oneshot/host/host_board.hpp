/// @file host_board.hpp
/// @brief Host port of the board contract: the harness plays clock, timer, ADC, PWM.
///
/// The static classes read and write the HostBoardState made current on this thread
/// (ScopedHostBoard), so several simulations can run on several threads at once. The
/// harness sets the time, the next actuation instant, the ADC and set-point codes before
/// it calls the firmware, and collects the PWM writes afterwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "oneshot/hal/board_contract.hpp"
#include "oneshot/hal/thread_current.hpp"

namespace oneshot::host {

/// A PWM register write made by the firmware.
struct PwmWrite {
  std::size_t channel;  ///< PWM channel.
  std::int32_t code;    ///< Duty code.
  std::uint64_t at_us;  ///< Clock value when written.
};

/// The emulated peripherals' registers.
struct HostBoardState {
  std::uint64_t now_us = 0;                 ///< The clock (64-bit µs: no wrap in any run).
  std::uint64_t next_actuation_us = 0;      ///< The actuation timer's compare value.
  std::vector<std::int32_t> adc_codes;      ///< What Adc::sample(ch) returns.
  /// Set-point schedule: code of channel ch valid at time t (µs); set by the harness.
  std::int32_t (*setpoint_at)(const void* context, std::size_t ch, std::uint64_t at_us) = nullptr;
  const void* setpoint_context = nullptr;   ///< Argument of setpoint_at.
  std::vector<PwmWrite> pwm_writes;         ///< Writes since the harness last cleared them.
};

/// Makes `state` the current board of this thread for its lifetime.
using ScopedHostBoard = hal::ScopedCurrent<HostBoardState>;

/// The current board state of this thread (asserts that one is set).
inline HostBoardState& current_board() { return ScopedHostBoard::current(); }

/// The board contract on the host.
struct HostBoard {
  /// The µs clock and the actuation timer, read together.
  struct Time {
    static hal::TimeSnapshot<std::uint64_t> snapshot() {
      const HostBoardState& b = current_board();
      return {HostInstant(b.now_us), HostInstant(b.next_actuation_us)};
    }
  };
  /// PWM duty registers.
  struct Pwm {
    static void write_duty(std::size_t channel, std::int32_t code) {
      HostBoardState& b = current_board();
      b.pwm_writes.push_back(PwmWrite{channel, code, b.now_us});
    }
  };
  /// ADC (conversion at the current time).
  struct Adc {
    static std::int32_t sample(std::size_t channel) { return current_board().adc_codes.at(channel); }
  };
  /// Set-point input (ADC code scale), valid at time at_us.
  struct Setpoint {
    static std::int32_t setpoint_code(std::size_t channel, HostInstant at) {
      const HostBoardState& b = current_board();
      return b.setpoint_at(b.setpoint_context, channel, at.ticks());
    }
  };
};

static_assert(hal::kHasTime<HostBoard> && hal::kHasPwm<HostBoard> && hal::kHasAdc<HostBoard> &&
              hal::kHasSetpointAt<HostBoard>);

}  // namespace oneshot::host
