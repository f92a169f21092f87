/// @file board_contract.hpp
/// @brief The peripherals a control task needs, as compile-time contracts.
///
/// A board is a struct of small static classes, injected as a template parameter:
///   Board::Clock      static std::uint32_t now_us();                 free-running µs time
///   Board::Timer      static std::uint32_t next_actuation_us();      compare value of the
///                                                                     actuation timer
///   Board::Pwm        static void write_duty(std::size_t ch, std::int32_t code);
///   Board::Adc        static std::int32_t sample(std::size_t ch);    converts now
///   Board::Setpoint   static std::int32_t setpoint_code(std::size_t ch, std::uint32_t at_us);
///                     the reference valid at time at_us, in ADC codes (a reference
///                     generator: the trajectory is known ahead of time)
/// Each is checked with a static_assert in the task that uses it; there is no virtual
/// dispatch on the control path. Ports: hal/host_sim (emulated board), hal/mcu.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace oneshot::hal {

namespace detail {
template <typename T, typename = void>
struct has_clock : std::false_type {};
template <typename T>
struct has_clock<T, std::enable_if_t<std::is_same_v<decltype(T::now_us()), std::uint32_t>>> : std::true_type {};

template <typename T, typename = void>
struct has_timer : std::false_type {};
template <typename T>
struct has_timer<T, std::enable_if_t<std::is_same_v<decltype(T::next_actuation_us()), std::uint32_t>>>
    : std::true_type {};

template <typename T, typename = void>
struct has_pwm : std::false_type {};
template <typename T>
struct has_pwm<T, std::void_t<decltype(T::write_duty(std::size_t{}, std::int32_t{}))>> : std::true_type {};

template <typename T, typename = void>
struct has_adc : std::false_type {};
template <typename T>
struct has_adc<T, std::enable_if_t<std::is_same_v<decltype(T::sample(std::size_t{})), std::int32_t>>>
    : std::true_type {};

template <typename T, typename = void>
struct has_setpoint : std::false_type {};
template <typename T>
struct has_setpoint<
    T, std::enable_if_t<std::is_same_v<decltype(T::setpoint_code(std::size_t{}, std::uint32_t{})), std::int32_t>>>
    : std::true_type {};
}  // namespace detail

/// Board::Clock fulfils the clock contract.
template <typename Board>
inline constexpr bool kHasClock = detail::has_clock<typename Board::Clock>::value;
/// Board::Timer fulfils the actuation-timer contract.
template <typename Board>
inline constexpr bool kHasTimer = detail::has_timer<typename Board::Timer>::value;
/// Board::Pwm fulfils the PWM contract.
template <typename Board>
inline constexpr bool kHasPwm = detail::has_pwm<typename Board::Pwm>::value;
/// Board::Adc fulfils the ADC contract.
template <typename Board>
inline constexpr bool kHasAdc = detail::has_adc<typename Board::Adc>::value;
/// Board::Setpoint fulfils the set-point contract.
template <typename Board>
inline constexpr bool kHasSetpoint = detail::has_setpoint<typename Board::Setpoint>::value;

}  // namespace oneshot::hal
