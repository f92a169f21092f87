/* The generated C job on an 8-bit AVR (16-bit int, like XC16's dsPIC target) under simavr.
 * The harness (c_job_avr_harness.c) drives it through the general-purpose I/O registers:
 *   GPIOR1, GPIOR2 <- address of `mailbox` (low, high byte), once at start
 *   GPIOR0 = 1: request; the harness fills the mailbox (command, variant, inputs) and reads
 *               the outputs of the previous command
 *   GPIOR0 = 3 / 4: start / end of a job (the harness counts the cycles between them)
 *   GPIOR0 = 5: finished.
 * Built with avr-gcc -std=c99 -pedantic -Wall -Wextra -Wconversion -Werror. */
#include <avr/io.h>
#include <avr/interrupt.h>
#include <avr/sleep.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "oneshot_job.h"

enum { kStop = 0, kInit = 1, kRun = 2 };

/* Shared with the harness: AVR structs have no padding; the offsets are checked below. */
struct mailbox_t {
  uint8_t command;      /* kStop, kInit, kRun */
  uint8_t variant;      /* 0 fixed_table, 1 fixed_nearest, 2 float_table, 3 float_nearest, 4 q15_table, 5 q15_nearest, 6 float_poly */
  int32_t tau_us;       /* run: inputs */
  uint16_t adc;
  uint16_t setpoint;
  uint16_t pwm;         /* init: the initial PWM code; run: the job's result */
  uint8_t status;
  uint8_t saturated;
  uint32_t x[ONESHOT_JOB_STATES];  /* raw: fixed mantissas sign-extended, float bit patterns */
  uint32_t k[ONESHOT_JOB_STATES];
  uint32_t u;
};
typedef char mailbox_layout_check[offsetof(struct mailbox_t, x) == 14 ? 1 : -1];

volatile struct mailbox_t mailbox;

static uint32_t bits_of(float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  return u;
}

#define OUTPUT_FIX(s)                                                       \
  do {                                                                      \
    uint8_t i;                                                              \
    mailbox.status = (s).status;                                            \
    mailbox.saturated = (s).saturated;                                      \
    for (i = 0; i < ONESHOT_JOB_STATES; ++i) {                              \
      mailbox.x[i] = (uint32_t)(int32_t)(s).x[i];                           \
      mailbox.k[i] = (uint32_t)(int32_t)(s).k[i];                           \
    }                                                                       \
    mailbox.u = (uint32_t)(int32_t)(s).u[0];                                \
  } while (0)
#define OUTPUT_FLT(s)                                                       \
  do {                                                                      \
    uint8_t i;                                                              \
    mailbox.status = (s).status;                                            \
    mailbox.saturated = 0u;                                                 \
    for (i = 0; i < ONESHOT_JOB_STATES; ++i) {                              \
      mailbox.x[i] = bits_of((s).x[i]);                                     \
      mailbox.k[i] = bits_of((s).k[i]);                                     \
    }                                                                       \
    mailbox.u = bits_of((s).u[0]);                                          \
  } while (0)
#define CLEAR_FIX(s) ((s).saturated = 0u)
#define CLEAR_FLT(s) ((void)0)

/* One command for variant V (KIND FIX or FLT). */
#define SERVE(V, KIND)                                                       \
  do {                                                                       \
    static oneshot_job_##V##_t s;                                            \
    if (mailbox.command == kInit) {                                          \
      oneshot_job_##V##_init(&s, mailbox.pwm);                               \
    } else {                                                                 \
      const int32_t tau = mailbox.tau_us;                                    \
      const uint16_t adc = mailbox.adc;                                      \
      const uint16_t sp = mailbox.setpoint;                                  \
      uint16_t pwm;                                                          \
      CLEAR_##KIND(s);                                                       \
      GPIOR0 = 3;                                                            \
      pwm = oneshot_job_##V##_run(&s, tau, adc, sp);                         \
      GPIOR0 = 4;                                                            \
      mailbox.pwm = pwm;                                                     \
      OUTPUT_##KIND(s);                                                      \
    }                                                                        \
  } while (0)

int main(void) {
  const uint16_t address = (uint16_t)(uintptr_t)&mailbox;
  GPIOR1 = (uint8_t)(address & 0xFFu);
  GPIOR2 = (uint8_t)(address >> 8);
  GPIOR0 = 3; /* an empty window: the markers' own cost */
  GPIOR0 = 4;
  for (;;) {
    GPIOR0 = 1;
    if (mailbox.command == kStop) break;
    switch (mailbox.variant) {
#if defined(ONESHOT_JOB_HAS_FIXED_TABLE)
      case 0: SERVE(fixed_table, FIX); break;
#endif
#if defined(ONESHOT_JOB_HAS_FIXED_NEAREST)
      case 1: SERVE(fixed_nearest, FIX); break;
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_TABLE)
      case 2: SERVE(float_table, FLT); break;
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_NEAREST)
      case 3: SERVE(float_nearest, FLT); break;
#endif
#if defined(ONESHOT_JOB_HAS_Q15_TABLE)
      case 4: SERVE(q15_table, FIX); break;
#endif
#if defined(ONESHOT_JOB_HAS_Q15_NEAREST)
      case 5: SERVE(q15_nearest, FIX); break;
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY)
      case 6: SERVE(float_poly, FLT); break;
#endif
      default: break;
    }
  }
  GPIOR0 = 5;
  cli();
  sleep_cpu(); /* simavr ends the run: sleeping with interrupts off */
  for (;;) {
  }
}
