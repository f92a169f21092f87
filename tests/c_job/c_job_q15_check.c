/* The q15 variant's arithmetic, defined and checked (strict C99 on the host compiler): the
 * saturating store, the division-free reciprocal (within 1 LSB of 2^(F_S + F_1/S)/v for every
 * 16-bit v, saturating where 1/v leaves the format), and one
 * prediction step's floor / round-half-up / saturate rules (q15_arith.hpp). The generated
 * file is included so that its static helpers can be called. Usage: c_job_q15_check */
#include <stdio.h>

#include "oneshot_job.c"

#if defined(ONESHOT_JOB_HAS_Q15_TABLE)
static int failures = 0;
#define CHECK(cond, ...)             \
  do {                               \
    if (!(cond)) {                   \
      ++failures;                    \
      fprintf(stderr, __VA_ARGS__);  \
      fprintf(stderr, "\n");         \
    }                                \
  } while (0)

static void check_saturation(void) {
  uint8_t sat = 0u;
  CHECK(os_q15_sat(123, &sat) == 123 && os_q15_sat(-123, &sat) == -123 && sat == 0u, "sat changed an in-range value");
  CHECK(os_q15_sat(32767, &sat) == 32767 && os_q15_sat(-32768, &sat) == -32768 && sat == 0u, "sat at the limits");
  CHECK(os_q15_sat(32768, &sat) == 32767 && sat == 1u, "sat above: clamp and flag");
  sat = 0u;
  CHECK(os_q15_sat(-32769, &sat) == -32768 && sat == 1u, "sat below: clamp and flag");
  sat = 0u;
  CHECK(os_q15_sat(INT32_C(0x18000), &sat) == 32767 && sat == 1u, "sat far above (would wrap): clamp and flag");
  sat = 0u;
  CHECK(os_q15_sat(INT32_MIN, &sat) == -32768 && sat == 1u, "sat at INT32_MIN: clamp and flag");
  CHECK(os_m16(-32768, -32768) == INT32_C(1073741824), "16x16 product of the extremes");
}

static void check_reciprocal(void) {
  const int shift = ONESHOT_JOB_Q15_TABLE_COVARIANCE_FRAC_BITS + ONESHOT_JOB_Q15_TABLE_INVERSE_COVARIANCE_FRAC_BITS;
  int32_t v;
  uint8_t sat = 0u;
  long worst = 0;
  for (v = 1; v <= 32767; ++v) {
    const double exact = (double)((int64_t)1 << shift) / (double)v;
    const int16_t q = q15_table_reciprocal((int16_t)v, &sat);
    if (exact < 32767.0) {
      const double err = (double)q - exact;
      CHECK(err <= 1.0 && err >= -1.0, "reciprocal(%ld) = %d, exact %.2f", (long)v, (int)q, exact);
      if ((long)(err < 0 ? -err : err) > worst) worst = (long)(err < 0 ? -err : err);
    } else {
      CHECK(q == INT16_MAX, "reciprocal(%ld) must saturate", (long)v);
    }
  }
  sat = 0u;
  CHECK(q15_table_reciprocal(0, &sat) == INT16_MAX && sat == 1u, "reciprocal(0): saturate and flag");
  printf("q15 reciprocal: every v in [1, 32767] within 1 LSB of 2^%d/v\n", shift);
}

/* The reference plant's triple (Phi(0,1); Gamma(0,0), (1,0); Q_d upper triangle). */
#if ONESHOT_JOB_STATES == 2 && ONESHOT_JOB_INPUTS == 1
static void check_prediction_rounding(void) {
  oneshot_job_q15_table_t s;
  q15_table_triple_t d;
  uint8_t sat = 0u;
  int16_t x0_half_up, x0_half_down;
  oneshot_job_q15_table_init(&s, 1000u);
  /* The identity interval changes nothing. */
  s.x[0] = 1234;
  s.x[1] = -77;
  d.phi[0] = 0;
  d.gamma[0] = 0;
  d.gamma[1] = 0;
  d.qd[0] = 0;
  d.qd[1] = 0;
  d.qd[2] = 0;
  q15_table_predict(&s, &d, &sat);
  CHECK(s.x[0] == 1234 && s.x[1] == -77 && sat == 0u, "identity prediction moved the estimate");
  /* Phi(0,1) = 1/2 in Q13: x0 + x1/2 with x1 = +-1 LSB is exactly half an LSB: half up. */
  d.phi[0] = (int16_t)(1 << 12);
  s.x[0] = 0;
  s.x[1] = 1;
  s.u[0] = 0;
  q15_table_predict(&s, &d, &sat);
  x0_half_up = s.x[0];
  s.x[0] = 0;
  s.x[1] = -1;
  q15_table_predict(&s, &d, &sat);
  x0_half_down = s.x[0];
  CHECK(x0_half_up == 1 && x0_half_down == 0, "round half up: got %d and %d", (int)x0_half_up, (int)x0_half_down);
  CHECK(sat == 0u, "no saturation expected");
  /* A prediction beyond the format saturates and raises the flag. */
  d.phi[0] = INT16_MAX;
  s.x[0] = INT16_MAX;
  s.x[1] = INT16_MAX;
  q15_table_predict(&s, &d, &sat);
  CHECK(s.x[0] == INT16_MAX && sat == 1u, "prediction beyond Q2.13 must saturate and flag");
}
#else
static void check_prediction_rounding(void) {}
#endif
#endif

int main(void) {
#if defined(ONESHOT_JOB_HAS_Q15_TABLE)
  check_saturation();
  check_reciprocal();
  check_prediction_rounding();
  printf("c_job_q15_check: %d failures\n", failures);
  return failures == 0 ? 0 : 1;
#else
  printf("skipped: no q15 variant for this plant\n");
  return 0;
#endif
}
