/// @file fixed_point_test.cpp
/// @brief Q-format arithmetic: rounding, saturation and its sticky flag, mixed formats.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <type_traits>

#include "oneshot/fixed_point.hpp"

namespace oneshot {
namespace {

using Q1_14 = Fixed<std::int16_t, 14>;
using Q3_28 = Fixed<std::int32_t, 28>;
using Q15Traits = ScalarTraits<Q15>;

static_assert(!std::is_same_v<Q15, Q1_14>, "Q formats are distinct types");
static_assert(!std::is_convertible_v<int, Q15>, "no implicit conversion from raw integers");
static_assert(!std::is_convertible_v<Q15, Q31>, "no implicit conversion between formats");
static_assert(ScalarTraits<Q1_14>::from_double(0.5).raw() == 8192, "constexpr conversion");

class FixedPoint : public ::testing::Test {
 protected:
  void SetUp() override { clear_saturation_flag(); }
};

TEST_F(FixedPoint, RoundsToNearestTiesUpward) {
  using Half = Fixed<std::int16_t, 1>;
  using Whole = Fixed<std::int16_t, 0>;
  EXPECT_EQ(convert<Whole>(Half::from_raw(3)).raw(), 2);    // 1.5 → 2
  EXPECT_EQ(convert<Whole>(Half::from_raw(-3)).raw(), -1);  // −1.5 → −1 (ties upward)
  EXPECT_EQ(convert<Whole>(Half::from_raw(-5)).raw(), -2);  // −2.5 → −2
  EXPECT_EQ(convert<Whole>(Half::from_raw(1)).raw(), 1);    // 0.5 → 1
  using Quarter = Fixed<std::int16_t, 2>;
  EXPECT_EQ(convert<Whole>(Quarter::from_raw(-7)).raw(), -2);  // −1.75 → −2
  EXPECT_EQ(convert<Whole>(Quarter::from_raw(-5)).raw(), -1);  // −1.25 → −1
  // Integer codes round as std::lround does: halves away from zero.
  EXPECT_EQ(ScalarTraits<Half>::round_to_int(Half::from_raw(-3)), -2);
  EXPECT_EQ(ScalarTraits<Half>::round_to_int(Half::from_raw(3)), 2);
  EXPECT_EQ(mul<Q15>(Q15Traits::from_double(0.5), Q15Traits::from_double(0.5)).raw(), 8192);
  EXPECT_FALSE(saturation_flag());
}

TEST_F(FixedPoint, SaturatesAndRaisesTheStickyFlag) {
  const Q15 big = Q15Traits::from_double(0.9);
  const Q15 sum = big + big;
  EXPECT_EQ(sum.raw(), 32767);
  EXPECT_TRUE(saturation_flag());
  const Q15 fine = Q15Traits::from_double(0.1) + Q15Traits::from_double(0.1);  // later exact operations keep it raised
  EXPECT_NEAR(Q15Traits::to_double(fine), 0.2, 1e-4);
  EXPECT_TRUE(saturation_flag());
  clear_saturation_flag();
  EXPECT_FALSE(saturation_flag());
  EXPECT_EQ((-Q15::from_raw(-32768)).raw(), 32767);  // −(−1) does not wrap
  EXPECT_TRUE(saturation_flag());
  clear_saturation_flag();
  const Q1_14 a = ScalarTraits<Q1_14>::from_double(1.9);
  EXPECT_EQ((a * a).raw(), 32767);  // 3.61 > 2 − 2⁻¹⁴
  EXPECT_TRUE(saturation_flag());
  clear_saturation_flag();
  EXPECT_EQ(ScalarTraits<Q15>::from_double(-3.0).raw(), -32768);
  EXPECT_TRUE(saturation_flag());
}

TEST_F(FixedPoint, ProductsAreExactBeforeTheOneRounding) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int32_t> i32(std::numeric_limits<std::int32_t>::min(),
                                                  std::numeric_limits<std::int32_t>::max());
  std::uniform_int_distribution<std::int32_t> i16(-32768, 32767);
  for (int k = 0; k < 100000; ++k) {
    const std::int32_t a = i32(rng);
    const auto b = static_cast<std::int16_t>(i16(rng));
    ASSERT_EQ(detail::wide_product(a, b), static_cast<std::int64_t>(a) * b) << a << " * " << b;
  }
  // Mixed formats: Q3.28 × Q1.14 → Q3.28 within half an LSB of the exact product.
  std::uniform_real_distribution<double> u(-1.9, 1.9);
  for (int k = 0; k < 10000; ++k) {
    const Q3_28 a = ScalarTraits<Q3_28>::from_double(u(rng) * 2);  // |a·b| < 7.3 stays inside ±8
    const Q1_14 b = ScalarTraits<Q1_14>::from_double(u(rng));
    const double exact = ScalarTraits<Q3_28>::to_double(a) * ScalarTraits<Q1_14>::to_double(b);
    EXPECT_LE(std::fabs(ScalarTraits<Q3_28>::to_double(mul<Q3_28>(a, b)) - exact), 0.5 * Q3_28::resolution());
  }
  EXPECT_FALSE(saturation_flag());
}

TEST_F(FixedPoint, AccumulatorRoundsOnceAtTheEnd) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 1000; ++trial) {
    Accumulator<Q1_14> acc;
    double exact = 0;
    for (int k = 0; k < 8; ++k) {
      const Q15 a = Q15Traits::from_double(u(rng) * 0.5);
      const Q15 b = Q15Traits::from_double(u(rng) * 0.5);
      acc.add_product(a, b);
      exact += Q15Traits::to_double(a) * Q15Traits::to_double(b);
    }
    // The 16 guard bits make the sum exact before the final rounding.
    EXPECT_LE(std::fabs(ScalarTraits<Q1_14>::to_double(acc.value()) - exact), 0.5 * Q1_14::resolution() + 1e-12);
  }
}

TEST_F(FixedPoint, ReciprocalAndItsFailure) {
  using Cov = Fixed<std::int32_t, 36>;
  using Inv = Fixed<std::int32_t, 16>;
  const Cov s = ScalarTraits<Cov>::from_double(8e-5);
  EXPECT_NEAR(ScalarTraits<Inv>::to_double(reciprocal<Inv>(s)), 12500, 0.01);
  EXPECT_FALSE(saturation_flag());
  reciprocal<Inv>(Cov{});
  EXPECT_TRUE(saturation_flag());
}

TEST_F(FixedPoint, Q31RoundTrip) {
  using T31 = ScalarTraits<Q31>;
  for (double v : {0.0, 0.25, -0.5, 0.999999, -1.0, 1e-9}) {
    EXPECT_NEAR(T31::to_double(T31::from_double(v)), v, Q31::resolution());
  }
  EXPECT_NEAR(T31::to_double(mul<Q31>(T31::from_double(0.3), T31::from_double(-0.7))), -0.21, 2 * Q31::resolution());
  EXPECT_FALSE(saturation_flag());
}

}  // namespace
}  // namespace oneshot
