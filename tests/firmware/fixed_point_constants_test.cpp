/// @file fixed_point_constants_test.cpp
/// @brief one() and from_ratio() in integer arithmetic: exact, rounded and saturated as before.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "oneshot/fixed_point.hpp"

namespace oneshot {
namespace {

__extension__ typedef __int128 Int128;  // GCC/Clang extension: the oracle's exact arithmetic

/// round(num·2^F/den), ties away from zero, in 128-bit integers (|num| < 2^40, F ≤ 62).
Int128 exact_ratio(std::int64_t num, std::int64_t den, int f) {
  Int128 n = num;
  Int128 d = den;
  if (f >= 0) {
    n *= static_cast<Int128>(1) << f;
  } else {
    d *= static_cast<Int128>(1) << -f;
  }
  if (d < 0) {
    n = -n;
    d = -d;
  }
  const bool negative = n < 0;
  const Int128 m = negative ? -n : n;
  const Int128 q = (2 * m + d) / (2 * d);  // floor(m/d + 1/2)
  return negative ? -q : q;
}

template <typename Q>
void check_format() {
  using T = ScalarTraits<Q>;
  using S = typename Q::StorageType;
  constexpr int kF = Q::kFrac;
  // one(): what from_double(1.0) gave, flag included.
  clear_saturation_flag();
  const auto by_double = T::from_double(1.0);
  const bool flag_double = saturation_flag();
  clear_saturation_flag();
  EXPECT_EQ(T::one().raw(), by_double.raw()) << kF;
  EXPECT_EQ(saturation_flag(), flag_double) << kF;
  // from_ratio(): the exact quotient, rounded, saturated with the flag.
  std::mt19937_64 rng(kF + 1000);
  std::uniform_int_distribution<std::int64_t> nums(-1'000'000, 1'000'000);
  std::uniform_int_distribution<std::int64_t> dens(1, 1'000'000);
  for (int i = 0; i < 20000; ++i) {
    const std::int64_t num = i < 200 ? (i % 20) - 10 : nums(rng);
    const std::int64_t den = (i < 200 ? i / 20 + 1 : dens(rng)) * (i % 3 == 0 ? -1 : 1);
    const Int128 exact = exact_ratio(num, den, kF);
    const bool fits = exact >= std::numeric_limits<S>::min() && exact <= std::numeric_limits<S>::max();
    clear_saturation_flag();
    const auto got = T::from_ratio(num, den);
    ASSERT_EQ(saturation_flag(), !fits) << num << "/" << den << " F=" << kF;
    const Int128 expected = fits ? exact : exact < 0 ? std::numeric_limits<S>::min() : std::numeric_limits<S>::max();
    ASSERT_EQ(static_cast<Int128>(got.raw()), expected) << num << "/" << den << " F=" << kF;
  }
  clear_saturation_flag();
}

TEST(FixedPointConstants, OneAndRatiosAreIntegerExact) {
  check_format<Fixed<std::int32_t, 29>>();
  check_format<Fixed<std::int32_t, 28>>();
  check_format<Fixed<std::int32_t, 0>>();
  check_format<Fixed<std::int32_t, 31>>();
  check_format<Fixed<std::int32_t, 46>>();
  check_format<Fixed<std::int32_t, -3>>();
  check_format<Fixed<std::int16_t, 13>>();
  check_format<Fixed<std::int16_t, 15>>();
  check_format<Fixed<std::int16_t, -2>>();
}

// Still usable in constant expressions.
static_assert(ScalarTraits<Fixed<std::int16_t, 14>>::one().raw() == 16384, "one() is constexpr");
static_assert(ScalarTraits<Fixed<std::int16_t, 14>>::from_ratio(-1, 3).raw() == -5461, "from_ratio() is constexpr");

}  // namespace
}  // namespace oneshot
