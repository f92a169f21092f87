/// @file c_job_host.hpp
/// @brief The generated q15 C99 job compiled into the host build, called job by job: the
///        oracle of the MCU's q15 job (same C, host gcc vs arm-none-eabi-gcc); likewise float_poly.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace oneshot::sim {

/// One q15 C job state (table or nearest variant) on the host.
class HostCJobQ15 {
 public:
  /// Starts it as oneshot_job_q15_<variant>_init(pwm0); std::invalid_argument when the
  /// generated job has no q15 variant.
  HostCJobQ15(bool nearest, std::uint16_t pwm0);
  ~HostCJobQ15();
  HostCJobQ15(const HostCJobQ15&) = delete;
  HostCJobQ15& operator=(const HostCJobQ15&) = delete;
  /// One job; returns the raw values the firmware reports: u[0], x[0..n), k[0].
  std::vector<std::int32_t> run(std::int32_t tau_us, std::uint16_t adc_code, std::uint16_t setpoint_code);
  /// True when the generated C job has the q15 variants.
  static bool available();

 private:
  struct State;
  std::unique_ptr<State> s_;
};

/// The float_poly C job state on the host (the oracle of approach 6 in the float table images).
class HostCJobFloatPoly {
 public:
  /// Starts it as oneshot_job_float_poly_init(pwm0); std::invalid_argument when the generated
  /// job has no float_poly variant.
  explicit HostCJobFloatPoly(std::uint16_t pwm0);
  ~HostCJobFloatPoly();
  HostCJobFloatPoly(const HostCJobFloatPoly&) = delete;
  HostCJobFloatPoly& operator=(const HostCJobFloatPoly&) = delete;
  /// One job; returns the IEEE bits the firmware reports: u[0], x[0..n), k[0].
  std::vector<std::int32_t> run(std::int32_t tau_us, std::uint16_t adc_code, std::uint16_t setpoint_code);
  /// True when the generated C job has the float_poly variant.
  static bool available();

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace oneshot::sim
