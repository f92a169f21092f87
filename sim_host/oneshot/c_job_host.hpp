/// @file c_job_host.hpp
/// @brief The generated C99 jobs with their own arithmetic (q15 table / nearest, float_poly)
///        compiled into the host build, called job by job: the oracle of the MCU's job (same
///        C, host gcc vs arm-none-eabi-gcc).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace oneshot::sim {

/// One host-compiled C job state of a variant with its own arithmetic.
class HostCJob {
 public:
  /// The variants: q15 with the τ table, q15 nearest-entry, float with the polynomial.
  enum class Variant : std::uint8_t { kQ15Table, kQ15Nearest, kFloatPoly };
  /// Starts it as oneshot_job_<variant>_init(pwm0); std::invalid_argument when the generated
  /// job does not have that variant.
  HostCJob(Variant variant, std::uint16_t pwm0);
  ~HostCJob();
  HostCJob(const HostCJob&) = delete;
  HostCJob& operator=(const HostCJob&) = delete;
  /// One job; returns the words the firmware reports: u[0], x[0..n), k[0] (q15: the raw
  /// values; float: the IEEE bits).
  std::vector<std::int32_t> run(std::int32_t tau_us, std::uint16_t adc_code, std::uint16_t setpoint_code);
  /// True when the generated C job has `variant`.
  static bool available(Variant variant);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace oneshot::sim
