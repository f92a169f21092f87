/* The division-free reciprocal of the generated fixed-point job against the C++ core's
 * algorithm (normalisation loops and a real division, ported here): os_div31 for every
 * 16-bit mantissa, the whole reciprocal for every v up to 2^20, around every power-of-two
 * boundary, and for a pseudo-random sweep of int32. Compiled as strict C99; includes the
 * generated oneshot_job.c to reach its static functions. Usage: c_job_division_check */
#include "oneshot_job.c"

#include <stdio.h>

#if defined(ONESHOT_JOB_HAS_FIXED_TABLE)
#define KSHIFT (ONESHOT_JOB_FIXED_TABLE_COVARIANCE_FRAC_BITS + ONESHOT_JOB_FIXED_TABLE_INVERSE_COVARIANCE_FRAC_BITS)

/* reciprocal<InverseCovariance>(Fixed<int32_t, F> v) of fixed_point.hpp, with a real division. */
static int32_t reference_reciprocal(int32_t v, uint8_t *sat) {
  uint32_t m, q;
  int e = 0;
  int shift;
  int64_t r;
  if (v <= 0) {
    *sat = 1u;
    return INT32_MAX;
  }
  m = (uint32_t)v;
  while (m >= UINT32_C(65536)) {
    m = (m + 1u) >> 1;
    ++e;
  }
  while (m < UINT32_C(32768)) {
    m <<= 1;
    --e;
  }
  if (m >= UINT32_C(65536)) {
    m >>= 1;
    ++e;
  }
  q = (UINT32_C(0x80000000) + m / 2u) / m;
  shift = 31 + e - KSHIFT;
  r = shift <= 0 ? (int64_t)q * ((int64_t)1 << -shift) : ((int64_t)q + ((int64_t)1 << (shift - 1))) >> shift;
  if (r > (int64_t)INT32_MAX) {
    *sat = 1u;
    return INT32_MAX;
  }
  return (int32_t)r;
}

static long compare(int32_t v) {
  uint8_t sat_got = 0u, sat_want = 0u;
  const int32_t got = fixed_table_reciprocal(v, &sat_got);
  const int32_t want = reference_reciprocal(v, &sat_want);
  if (got != want || sat_got != sat_want) {
    fprintf(stderr, "reciprocal(%ld): %ld (sat %d), core %ld (sat %d)\n", (long)v, (long)got, sat_got, (long)want,
            sat_want);
    return 1;
  }
  return 0;
}

int main(void) {
  long bad = 0, tested = 0;
  uint32_t m, s, lcg = 12345u;
  int32_t v;
  int d;
  for (m = UINT32_C(32768); m < UINT32_C(65536); ++m) {
    const uint32_t want = (UINT32_C(0x80000000) + m / 2u) / m;
    if (os_div31(m) != want) {
      if (bad++ < 5) fprintf(stderr, "os_div31(%lu) = %lu, want %lu\n", (unsigned long)m, (unsigned long)os_div31(m),
                             (unsigned long)want);
    }
    ++tested;
  }
  for (v = -3; v <= (INT32_C(1) << 20); ++v, ++tested) bad += compare(v);
  for (s = 0; s < 16u; ++s)
    for (d = -3; d <= 3; ++d) {
      const int64_t base = (int64_t)UINT32_C(65535) << s;
      bad += compare((int32_t)(base + d));
      bad += compare((int32_t)(((int64_t)1 << (s + 16)) + d));
      tested += 2;
    }
  bad += compare(INT32_MAX);
  for (s = 0; s < 2000000u; ++s, ++tested) {
    lcg = lcg * UINT32_C(1664525) + UINT32_C(1013904223);
    bad += compare((int32_t)(lcg >> 1));
  }
  printf("c_job_division_check: %ld values, %ld different from the core's reciprocal\n", tested, bad);
  return bad == 0 ? 0 : 1;
}
#else
int main(void) {
  printf("c_job_division_check: no fixed-point variant generated for this plant\n");
  return 0;
}
#endif
