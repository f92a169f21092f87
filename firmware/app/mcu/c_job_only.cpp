/// @file c_job_only.cpp
/// @brief The smallest image around the generated C99 job (no PIL link), for its flash and
///        RAM: the job runs on volatile inputs and its PWM code goes to a volatile register
///        written by the actuation interrupt, as on a board. Never run; measured with size.
#include <cstdint>

#include "oneshot_job.h"

#define ONESHOT_CJOB_CAT2(a, b) a##b
#define ONESHOT_CJOB_CAT(a, b) ONESHOT_CJOB_CAT2(a, b)
#define ONESHOT_CJOB(name) ONESHOT_CJOB_CAT(ONESHOT_CJOB_CAT(ONESHOT_CJOB_CAT(oneshot_job_, ONESHOT_CJOB_VARIANT), _), name)

// ONESHOT_CJOB_HAS names the header's ONESHOT_JOB_HAS_<VARIANT>: 0 when the plant lacks it.
#if ONESHOT_CJOB_HAS
namespace {
ONESHOT_CJOB(t) g_job;
volatile std::int32_t g_tau_us;       // stands for the timer capture
volatile std::uint16_t g_adc;         // stands for ADC1BUF0
volatile std::uint16_t g_setpoint;
volatile std::uint16_t g_prepared;
volatile bool g_run;
volatile std::uint16_t g_pwm_register;  // stands for PDC1
}  // namespace

/// The actuation interrupt: the prepared code goes out (the other vectors: startup.cpp's).
extern "C" void oneshot_actuation_timer_handler() { g_pwm_register = g_prepared; }
/// Stands for the sampling instant's interrupt.
extern "C" void oneshot_idle_wakeup_handler() { g_run = true; }

int main() {
  ONESHOT_CJOB(init)(&g_job, static_cast<std::uint16_t>(ONESHOT_JOB_PWM_STEPS / 2));
  for (;;) {
    if (g_run) {
      g_run = false;
      g_prepared = ONESHOT_CJOB(run)(&g_job, g_tau_us, g_adc, g_setpoint);
    }
  }
}
#else
int main() {}  // this plant has no such variant
#endif
