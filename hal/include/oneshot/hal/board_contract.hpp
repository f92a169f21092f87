/// @file board_contract.hpp
/// @brief The peripherals a control task needs, as compile-time contracts.
///
/// A board is a struct of small static classes, injected as a template parameter:
///   Board::Time       static TimeSnapshot<Rep> snapshot();           the free-running µs
///                     clock and the actuation timer's compare value, read together (one
///                     critical section on an MCU, so τ never mixes two timer periods), as
///                     wrap-safe instants (time_us.hpp): Rep = uint32_t on an MCU's 32-bit
///                     timer, uint64_t on the host (no wrap in any run)
///   Board::Pwm        static void write_duty(std::size_t ch, std::int32_t code);
///   Board::Adc        static std::int32_t sample(std::size_t ch);    converts now
///   Board::Setpoint   static std::int32_t setpoint_code(std::size_t ch, InstantUs<Rep> at);
///                     the reference valid at instant `at`, in ADC codes (a reference
///                     generator: the trajectory is known ahead of time)
/// Each is checked with a static_assert in the task that uses it; there is no virtual
/// dispatch on the control path. Ports: hal/host_sim (emulated board), hal/mcu.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/time_us.hpp"

namespace oneshot::hal {

/// The clock and the actuation timer read as one snapshot.
template <typename Rep>
struct TimeSnapshot {
  InstantUs<Rep> now;             ///< Free-running µs clock.
  InstantUs<Rep> next_actuation;  ///< Compare value of the actuation timer.
};

namespace detail {
template <typename T, typename = void>
struct has_pwm : std::false_type {};
template <typename T>
struct has_pwm<T, std::void_t<decltype(T::write_duty(std::size_t{}, std::int32_t{}))>> : std::true_type {};

template <typename T, typename = void>
struct has_adc : std::false_type {};
template <typename T>
struct has_adc<T, std::enable_if_t<std::is_same_v<decltype(T::sample(std::size_t{})), std::int32_t>>>
    : std::true_type {};

template <typename T>
struct is_time_snapshot : std::false_type {};
template <typename Rep>
struct is_time_snapshot<TimeSnapshot<Rep>> : std::true_type {};

template <typename T, typename = void>
struct has_time : std::false_type {};
template <typename T>
struct has_time<T, std::enable_if_t<is_time_snapshot<decltype(T::snapshot())>::value>> : std::true_type {};

template <typename T, typename Instant, typename = void>
struct has_setpoint_at : std::false_type {};
template <typename T, typename Instant>
struct has_setpoint_at<
    T, Instant, std::enable_if_t<std::is_same_v<decltype(T::setpoint_code(std::size_t{}, Instant{})), std::int32_t>>>
    : std::true_type {};
}  // namespace detail

/// Board::Time fulfils the time-snapshot contract.
template <typename Board>
inline constexpr bool kHasTime = detail::has_time<typename Board::Time>::value;
/// The instant type of a board with the Time contract.
template <typename Board>
using InstantOf = decltype(Board::Time::snapshot().now);
/// Board::Setpoint takes the board's instants (needs kHasTime).
template <typename Board>
inline constexpr bool kHasSetpointAt = detail::has_setpoint_at<typename Board::Setpoint, InstantOf<Board>>::value;

/// Board::Pwm fulfils the PWM contract.
template <typename Board>
inline constexpr bool kHasPwm = detail::has_pwm<typename Board::Pwm>::value;
/// Board::Adc fulfils the ADC contract.
template <typename Board>
inline constexpr bool kHasAdc = detail::has_adc<typename Board::Adc>::value;

}  // namespace oneshot::hal
