/// @file c_job_host.cpp
/// @brief The host-compiled C jobs with their own arithmetic (see c_job_host.hpp).
#include "c_job_host.hpp"

#include <cstring>
#include <stdexcept>

#include "oneshot_job.h"

namespace oneshot::sim {

namespace {
#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
constexpr bool kHasQ15 = true;
#else
constexpr bool kHasQ15 = false;
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
constexpr bool kHasFloatPoly = true;
#else
constexpr bool kHasFloatPoly = false;
#endif

/// The word the firmware reports for a value: q15 raw, float as its IEEE bits.
[[maybe_unused]] std::int32_t word(std::int16_t v) { return v; }
[[maybe_unused]] std::int32_t word(float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return static_cast<std::int32_t>(u);
}

/// u[0], x[0..n), k[0] of a job state, as words.
template <class S>
std::vector<std::int32_t> report(const S& st) {
  std::vector<std::int32_t> out{word(st.u[0])};
  for (std::size_t i = 0; i < ONESHOT_JOB_STATES; ++i) out.push_back(word(st.x[i]));
  out.push_back(word(st.k[0]));
  return out;
}
}  // namespace

struct HostCJob::State {
  Variant variant = Variant::kQ15Table;
#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
  oneshot_job_q15_table_t table{};
  oneshot_job_q15_nearest_t near{};
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
  oneshot_job_float_poly_t poly{};
#endif
};

bool HostCJob::available(Variant variant) { return variant == Variant::kFloatPoly ? kHasFloatPoly : kHasQ15; }

HostCJob::HostCJob(Variant variant, std::uint16_t pwm0) : s_(std::make_unique<State>()) {
  if (!available(variant)) throw std::invalid_argument("the generated C job does not have this own-arithmetic variant");
  s_->variant = variant;
  switch (variant) {
#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
    case Variant::kQ15Table: oneshot_job_q15_table_init(&s_->table, pwm0); break;
    case Variant::kQ15Nearest: oneshot_job_q15_nearest_init(&s_->near, pwm0); break;
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
    case Variant::kFloatPoly: oneshot_job_float_poly_init(&s_->poly, pwm0); break;
#endif
    default: break;
  }
}

HostCJob::~HostCJob() = default;

std::vector<std::int32_t> HostCJob::run(std::int32_t tau_us, std::uint16_t adc_code, std::uint16_t setpoint_code) {
  switch (s_->variant) {
#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
    case Variant::kQ15Table:
      oneshot_job_q15_table_run(&s_->table, tau_us, adc_code, setpoint_code);
      return report(s_->table);
    case Variant::kQ15Nearest:
      oneshot_job_q15_nearest_run(&s_->near, tau_us, adc_code, setpoint_code);
      return report(s_->near);
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
    case Variant::kFloatPoly:
      oneshot_job_float_poly_run(&s_->poly, tau_us, adc_code, setpoint_code);
      return report(s_->poly);
#endif
    default: return {};  // unreachable: the constructor refuses a variant the job lacks
  }
}

}  // namespace oneshot::sim
