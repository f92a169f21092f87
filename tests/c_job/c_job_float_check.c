/* The float variants' integer helpers against the host's IEEE single arithmetic, bit for bit:
 * os_fmul with ONESHOT_JOB_INTEGER_FLOAT (the Cortex-M0 path) against a * b on random operand
 * pairs (every class: zeros, subnormals, infinities, NaNs) and on pairs built to hit the
 * rounding ties and the edges of the normal range; os_f32_of_u16 against (float) on every
 * 16-bit value; os_f32_trunc against (int32_t) on every k and k + 1/2 and on a sweep of
 * [0, 2^23); os_f32_positive against 0 < v on a sweep of all bit patterns and the special
 * values. Random streams: xorshift32, one fixed seed per stream. Usage: c_job_float_check */
#define ONESHOT_JOB_INTEGER_FLOAT 1
#include "oneshot_job.c"

#include <stdio.h>
#include <string.h>

static uint32_t rng_state;
static uint32_t next_random(void) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 17;
  rng_state ^= rng_state << 5;
  return rng_state;
}

static float of_bits(uint32_t u) {
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

static uint32_t bits_of(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

static long fmul_mismatches(uint32_t ua, uint32_t ub) {
  const float a = of_bits(ua);
  const float b = of_bits(ub);
  const volatile float hw = a * b;
  const uint32_t want = bits_of(hw);
  const uint32_t got = bits_of(os_fmul(a, b));
  const int both_nan = (want & UINT32_C(0x7FFFFFFF)) > UINT32_C(0x7F800000) && (got & UINT32_C(0x7FFFFFFF)) > UINT32_C(0x7F800000);
  if (want == got || both_nan) return 0;
  fprintf(stderr, "os_fmul(%08lx, %08lx) = %08lx, a * b = %08lx\n", (unsigned long)ua, (unsigned long)ub,
          (unsigned long)got, (unsigned long)want);
  return 1;
}

static long check_fmul(void) {
  long bad = 0, n = 0;
  long k;
  rng_state = UINT32_C(0x2545F491);  /* random bit patterns: every class */
  for (k = 0; k < 4000000L; ++k, ++n) bad += fmul_mismatches(next_random(), next_random());
  rng_state = UINT32_C(0x9E3779B9);  /* normal operands with few significant bits: many exact ties */
  for (k = 0; k < 4000000L; ++k, ++n) {
    const uint32_t keep_a = UINT32_C(0xFFFFFFFF) << (next_random() % 24u);
    const uint32_t keep_b = UINT32_C(0xFFFFFFFF) << (next_random() % 24u);
    const uint32_t ea = 64u + next_random() % 128u, eb = 64u + next_random() % 128u;
    const uint32_t ua = (next_random() & UINT32_C(0x80000000)) | (ea << 23) | (next_random() & UINT32_C(0x7FFFFF) & keep_a);
    const uint32_t ub = (next_random() & UINT32_C(0x80000000)) | (eb << 23) | (next_random() & UINT32_C(0x7FFFFF) & keep_b);
    bad += fmul_mismatches(ua, ub);
  }
  rng_state = UINT32_C(0x68E31DA4);  /* exponent sums at the edges of the normal range */
  for (k = 0; k < 4000000L; ++k, ++n) {
    const uint32_t ea = 1u + next_random() % 254u;
    const uint32_t sum = (next_random() & 1u) ? 120u + next_random() % 12u : 375u + next_random() % 12u;
    const uint32_t eb = sum > ea && sum - ea >= 1u && sum - ea <= 254u ? sum - ea : 127u;
    const uint32_t ua = (next_random() & UINT32_C(0x807FFFFF)) | (ea << 23);
    const uint32_t ub = (next_random() & UINT32_C(0x807FFFFF)) | (eb << 23);
    bad += fmul_mismatches(ua, ub);
  }
  printf("os_fmul: %ld operand pairs, %ld different from a * b\n", n, bad);
  return bad;
}

static long check_conversions(void) {
  long bad = 0;
  uint32_t v, u;
  for (v = 0u; v <= UINT32_C(0xFFFF); ++v)
    if (bits_of(os_f32_of_u16(v)) != bits_of((float)v)) ++bad;
  for (v = 0u; v <= UINT32_C(0x10000); ++v) {
    const float whole = (float)v, half = (float)v + 0.5f;
    if (os_f32_trunc(whole) != (int32_t)whole || os_f32_trunc(half) != (int32_t)half) ++bad;
  }
  for (u = 0u; u < UINT32_C(0x4B000000); u += 997u)
    if (os_f32_trunc(of_bits(u)) != (int32_t)of_bits(u)) ++bad;
  printf("os_f32_of_u16, os_f32_trunc: %ld differences from the C conversions\n", bad);
  return bad;
}

static long check_positive(void) {
  static const uint32_t special[] = {0u, 1u, UINT32_C(0x007FFFFF), UINT32_C(0x00800000), UINT32_C(0x3F800000),
                                     UINT32_C(0x7F7FFFFF), UINT32_C(0x7F800000), UINT32_C(0x7F800001),
                                     UINT32_C(0x7FC00000), UINT32_C(0x7FFFFFFF), UINT32_C(0x80000000),
                                     UINT32_C(0x80000001), UINT32_C(0xBF800000), UINT32_C(0xFF800000),
                                     UINT32_C(0xFFC00000), UINT32_C(0xFFFFFFFF)};
  long bad = 0;
  size_t i;
  uint32_t u = 0u;
  for (i = 0; i < sizeof special / sizeof special[0]; ++i)
    if (os_f32_positive(of_bits(special[i])) != (0.0f < of_bits(special[i]))) ++bad;
  do {
    if (os_f32_positive(of_bits(u)) != (0.0f < of_bits(u))) ++bad;
    u += 65521u;
  } while (u >= 65521u);
  printf("os_f32_positive: %ld differences from 0 < v\n", bad);
  return bad;
}

int main(void) {
  const long bad = check_fmul() + check_conversions() + check_positive();
  printf("c_job_float_check: %s\n", bad == 0 ? "all bit-identical" : "DIFFERENCES");
  return bad == 0 ? 0 : 1;
}
