/* The generated C job against the C++ core (the q15 variants and float_poly: against the same C compiled into
 * the reference writer, with other flags), compiled by the host C compiler as strict C99
 * (-std=c99 -pedantic -Wall -Wextra -Wconversion -Werror): every job of the reference file
 * must give the same PWM code, status, saturation flag, estimate, gain and applied input,
 * bit for bit. Usage: c_job_check REFERENCE_FILE */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "c_job_reference_file.h"
#include "oneshot_job.h"

static long long raw_float(float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  return (long long)u;
}
#define RAW_FIX(v) ((long long)(v))
#define RAW_FLT(v) raw_float(v)
#define SAT_FIX(s) ((int)(s).saturated)
#define SAT_FLT(s) 0
#define CLEAR_FIX(s) ((s).saturated = 0u)
#define CLEAR_FLT(s) ((void)0)

/* Runs variant V (KIND FIX or FLT) over the jobs of r; returns the number of mismatches. */
#define DEFINE_CHECK(V, KIND)                                                                             \
  static long check_##V(const ref_variant_t *r, long statuses[4], long *saturated) {                      \
    oneshot_job_##V##_t s;                                                                                \
    long bad = 0;                                                                                         \
    int j, i;                                                                                             \
    oneshot_job_##V##_init(&s, (uint16_t)r->pwm0);                                                        \
    for (j = 0; j < r->count; ++j) {                                                                      \
      const ref_job_t *e = &r->jobs[j];                                                                   \
      int same;                                                                                           \
      uint16_t pwm;                                                                                       \
      CLEAR_##KIND(s);                                                                                    \
      pwm = oneshot_job_##V##_run(&s, (int32_t)e->tau_us, (uint16_t)e->adc, (uint16_t)e->setpoint);     \
      same = pwm == e->pwm && s.status == e->status && SAT_##KIND(s) == e->saturated &&                  \
             RAW_##KIND(s.u[0]) == e->u;                                                                  \
      for (i = 0; i < ONESHOT_JOB_STATES; ++i)                                                            \
        same = same && RAW_##KIND(s.x[i]) == e->x[i] && RAW_##KIND(s.k[i]) == e->k[i];                    \
      if (s.status < 4) ++statuses[s.status];                                                             \
      if (SAT_##KIND(s)) ++*saturated;                                                                    \
      if (!same && bad++ < 5) {                                                                           \
        fprintf(stderr, "%s job %d (tau %ld, adc %d, sp %d): pwm %u/%d status %d/%d sat %d/%d x0 %lld/%lld " \
                        "k0 %lld/%lld u %lld/%lld\n",                                                     \
                #V, j, e->tau_us, e->adc, e->setpoint, (unsigned)pwm, e->pwm, (int)s.status, e->status,  \
                SAT_##KIND(s), e->saturated, RAW_##KIND(s.x[0]), e->x[0], RAW_##KIND(s.k[0]), e->k[0],    \
                RAW_##KIND(s.u[0]), e->u);                                                                \
      }                                                                                                   \
    }                                                                                                     \
    return bad;                                                                                           \
  }

#if defined(ONESHOT_JOB_HAS_FIXED_TABLE)
DEFINE_CHECK(fixed_table, FIX)
#endif
#if defined(ONESHOT_JOB_HAS_FIXED_NEAREST)
DEFINE_CHECK(fixed_nearest, FIX)
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_TABLE)
DEFINE_CHECK(float_table, FLT)
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_NEAREST)
DEFINE_CHECK(float_nearest, FLT)
#endif
#if defined(ONESHOT_JOB_HAS_Q15_TABLE)
DEFINE_CHECK(q15_table, FIX)
#endif
#if defined(ONESHOT_JOB_HAS_Q15_NEAREST)
DEFINE_CHECK(q15_nearest, FIX)
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY)
DEFINE_CHECK(float_poly, FLT)
#endif

int main(int argc, char **argv) {
  static ref_file_t ref;
  int v, checked = 0, failed = 0;
  if (argc != 2) {
    fprintf(stderr, "usage: c_job_check REFERENCE_FILE\n");
    return 2;
  }
  if (ref_read(argv[1], &ref) != 0) return 1;
  if (ref.states != ONESHOT_JOB_STATES) {
    fprintf(stderr, "reference has %d states, the job %d\n", ref.states, ONESHOT_JOB_STATES);
    return 1;
  }
  for (v = 0; v < ref.variant_count; ++v) {
    const ref_variant_t *r = &ref.variants[v];
    long statuses[4] = {0, 0, 0, 0};
    long saturated = 0;
    long bad = -1;
#if defined(ONESHOT_JOB_HAS_FIXED_TABLE)
    if (strcmp(r->name, "fixed_table") == 0) bad = check_fixed_table(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_FIXED_NEAREST)
    if (strcmp(r->name, "fixed_nearest") == 0) bad = check_fixed_nearest(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_TABLE)
    if (strcmp(r->name, "float_table") == 0) bad = check_float_table(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_NEAREST)
    if (strcmp(r->name, "float_nearest") == 0) bad = check_float_nearest(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_Q15_TABLE)
    if (strcmp(r->name, "q15_table") == 0) bad = check_q15_table(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_Q15_NEAREST)
    if (strcmp(r->name, "q15_nearest") == 0) bad = check_q15_nearest(r, statuses, &saturated);
#endif
#if defined(ONESHOT_JOB_HAS_FLOAT_POLY)
    if (strcmp(r->name, "float_poly") == 0) bad = check_float_poly(r, statuses, &saturated);
#endif
    if (bad < 0) {
      fprintf(stderr, "variant %s: not in the generated job\n", r->name);
      ++failed;
      continue;
    }
    printf("%s: %d jobs, %ld bit-identical (PWM code, status, saturation, estimate, gain, applied input); "
           "statuses ok %ld, extended %ld, clamped %ld, singular %ld; saturated %ld\n",
           r->name, r->count, (long)r->count - bad, statuses[0], statuses[1], statuses[2], statuses[3], saturated);
    /* The sequence must reach the table's extension and clamping branches. A job reports the
       worst status of its steps, so an extension (h - tau beyond the range, tau < 0) shows as
       clamped (tau < 0 itself): count the jobs whose h - tau lies in (h, 4h], the extension
       path for a range of h (the reference plant; the generator requires range >= h). */
    {
      long extension_jobs = 0;
      int j;
      for (j = 0; j < r->count; ++j) {
        const long tau = r->jobs[j].tau_us;
        if (tau < 0 && tau >= -3L * (long)ONESHOT_JOB_PERIOD_US) ++extension_jobs;
      }
      printf("%s: %ld jobs through the extension path (h < h - tau <= 4h)\n", r->name, extension_jobs);
      if (bad != 0 || (statuses[1] == 0 && extension_jobs == 0) || statuses[2] == 0) ++failed;
    }
    ++checked;
  }
  printf("c_job_check: %d variants checked, %d with a difference or an unexercised branch\n", checked, failed);
  return failed == 0 && checked > 0 ? 0 : 1;
}
