/// @file pil_board.hpp
/// @brief The board contract on the MCU in processor-in-the-loop mode.
///
/// The harness plays the plant, the ADC and the clock: each kSample frame carries the
/// time, the next actuation instant, the ADC and set-point codes, which these static
/// classes return; PWM writes are collected and reported in the reply. The actuation
/// interrupt itself is a real timer interrupt of the SoC (nrf51.hpp, mps2_an386.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/board_contract.hpp"

namespace oneshot::mcu {

/// Largest number of PWM writes per request.
inline constexpr std::size_t kMaxPwmWrites = 8;
/// Largest number of outputs handled.
inline constexpr std::size_t kMaxChannels = 4;

/// The peripheral values of the current request.
struct PilRegisters {
  std::uint32_t now_us = 0;                  ///< Clock.
  std::uint32_t next_actuation_us = 0;       ///< Timer compare value.
  std::int32_t adc[kMaxChannels] = {};       ///< ADC codes.
  std::int32_t setpoint[kMaxChannels] = {};  ///< Set-point codes (valid when the job's output applies).
  std::uint8_t write_channel[kMaxPwmWrites] = {};  ///< PWM writes: channel.
  std::int32_t write_code[kMaxPwmWrites] = {};     ///< PWM writes: code.
  std::size_t writes = 0;                    ///< Number of PWM writes.
};

/// The registers (defined by the firmware).
extern PilRegisters g_pil;

/// Board contract backed by g_pil.
struct PilBoard {
  /// The µs clock and the actuation timer of this request (one frame: one snapshot).
  struct Time {
    static hal::TimeSnapshot<std::uint32_t> snapshot() {
      return {McuInstant(g_pil.now_us), McuInstant(g_pil.next_actuation_us)};
    }
  };
  /// PWM duty registers.
  struct Pwm {
    static void write_duty(std::size_t channel, std::int32_t code) {
      if (g_pil.writes < kMaxPwmWrites) {
        g_pil.write_channel[g_pil.writes] = static_cast<std::uint8_t>(channel);
        g_pil.write_code[g_pil.writes] = code;
        ++g_pil.writes;
      }
    }
  };
  /// ADC.
  struct Adc {
    static std::int32_t sample(std::size_t channel) { return g_pil.adc[channel]; }
  };
  /// Set-point (the harness sends the value for the instant the job asks about).
  struct Setpoint {
    static std::int32_t setpoint_code(std::size_t channel, McuInstant /*at*/) { return g_pil.setpoint[channel]; }
  };
};

static_assert(hal::kHasTime<PilBoard> && hal::kHasPwm<PilBoard> && hal::kHasAdc<PilBoard> &&
              hal::kHasSetpointAt<PilBoard>);

}  // namespace oneshot::mcu
