/// @file c_job_host.cpp
/// @brief The host-compiled q15 C job (see c_job_host.hpp).
#include "c_job_host.hpp"

#include <cstring>
#include <stdexcept>

#include "oneshot_job.h"

namespace oneshot::sim {

#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
struct HostCJobQ15::State {
  bool nearest = false;
  oneshot_job_q15_table_t table{};
  oneshot_job_q15_nearest_t near{};
};

HostCJobQ15::HostCJobQ15(bool nearest, std::uint16_t pwm0) : s_(std::make_unique<State>()) {
  s_->nearest = nearest;
  if (nearest) {
    oneshot_job_q15_nearest_init(&s_->near, pwm0);
  } else {
    oneshot_job_q15_table_init(&s_->table, pwm0);
  }
}

std::vector<std::int32_t> HostCJobQ15::run(std::int32_t tau_us, std::uint16_t adc_code, std::uint16_t setpoint_code) {
  std::vector<std::int32_t> out;
  const auto report = [&](const auto& st) {
    out.push_back(st.u[0]);
    for (std::size_t i = 0; i < ONESHOT_JOB_STATES; ++i) out.push_back(st.x[i]);
    out.push_back(st.k[0]);
  };
  if (s_->nearest) {
    oneshot_job_q15_nearest_run(&s_->near, tau_us, adc_code, setpoint_code);
    report(s_->near);
  } else {
    oneshot_job_q15_table_run(&s_->table, tau_us, adc_code, setpoint_code);
    report(s_->table);
  }
  return out;
}

bool HostCJobQ15::available() { return true; }
#else
struct HostCJobQ15::State {};
HostCJobQ15::HostCJobQ15(bool, std::uint16_t) { throw std::invalid_argument("the generated C job has no q15 variant"); }
std::vector<std::int32_t> HostCJobQ15::run(std::int32_t, std::uint16_t, std::uint16_t) { return {}; }
bool HostCJobQ15::available() { return false; }
#endif

HostCJobQ15::~HostCJobQ15() = default;

#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
struct HostCJobFloatPoly::State {
  oneshot_job_float_poly_t s{};
};

HostCJobFloatPoly::HostCJobFloatPoly(std::uint16_t pwm0) : s_(std::make_unique<State>()) {
  oneshot_job_float_poly_init(&s_->s, pwm0);
}

std::vector<std::int32_t> HostCJobFloatPoly::run(std::int32_t tau_us, std::uint16_t adc_code,
                                                 std::uint16_t setpoint_code) {
  oneshot_job_float_poly_run(&s_->s, tau_us, adc_code, setpoint_code);
  const auto bits = [](float v) {
    std::uint32_t u = 0;
    std::memcpy(&u, &v, sizeof u);
    return static_cast<std::int32_t>(u);
  };
  std::vector<std::int32_t> out{bits(s_->s.u[0])};
  for (std::size_t i = 0; i < ONESHOT_JOB_STATES; ++i) out.push_back(bits(s_->s.x[i]));
  out.push_back(bits(s_->s.k[0]));
  return out;
}

bool HostCJobFloatPoly::available() { return true; }
#else
struct HostCJobFloatPoly::State {};
HostCJobFloatPoly::HostCJobFloatPoly(std::uint16_t) {
  throw std::invalid_argument("the generated C job has no float_poly variant");
}
std::vector<std::int32_t> HostCJobFloatPoly::run(std::int32_t, std::uint16_t, std::uint16_t) { return {}; }
bool HostCJobFloatPoly::available() { return false; }
#endif

HostCJobFloatPoly::~HostCJobFloatPoly() = default;

}  // namespace oneshot::sim
