/// @file pattern_test.cpp
/// @brief Patterns beyond 64 entries (10–16-state structures): masks in several words,
///        transpose and row views, structured kernels equal to dense ones bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "oneshot/kalman_estimator.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/pattern.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {
namespace {

/// A 12×12 pattern: a block-diagonal chain of 2×2 integrators (Φ of six double integrators):
/// entries (2k, 2k+1) free, diagonal one, everything else zero — 144 entries, three words.
constexpr std::uint64_t word_of(std::size_t w, bool ones) {
  std::uint64_t out = 0;
  for (std::size_t b = 0; b < 64; ++b) {
    const std::size_t idx = w * 64 + b;
    if (idx >= 144) break;
    const std::size_t i = idx / 12;
    const std::size_t j = idx % 12;
    const bool one = i == j;
    const bool free = (i % 2 == 0) && j == i + 1;
    if (ones ? one : (!one && !free)) out |= std::uint64_t{1} << b;
  }
  return out;
}
using Chain12 = Pattern<12, 12, word_of(0, false), word_of(0, true), word_of(1, false), word_of(1, true),
                        word_of(2, false), word_of(2, true)>;

TEST(Pattern, TwelveStateStructureSpansThreeWords) {
  EXPECT_TRUE(Chain12::is_one(11, 11));
  EXPECT_TRUE(Chain12::is_free(10, 11));
  EXPECT_TRUE(Chain12::is_zero(11, 10));
  EXPECT_TRUE(Chain12::is_zero(0, 11));
  EXPECT_TRUE(Chain12::is_free(0, 1));
  // The transpose moves every entry, across words.
  using T = Transposed<Chain12>;
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = 0; j < 12; ++j) {
      EXPECT_EQ(T::is_zero(j, i), Chain12::is_zero(i, j));
      EXPECT_EQ(T::is_one(j, i), Chain12::is_one(i, j));
    }
  // A row view.
  using R = RowOf<Chain12, 10>;
  static_assert(R::kRows == 1 && R::kCols == 12);
  for (std::size_t j = 0; j < 12; ++j) EXPECT_EQ(R::is_free(0, j), Chain12::is_free(10, j));
  // The one-word spelling of small patterns is unchanged.
  static_assert(Pattern<2, 2, 0x6, 0x0>::is_zero(0, 1) && Pattern<2, 2, 0x6, 0x0>::is_free(0, 0));
  static_assert(Dense<16, 16>::is_free(15, 15) && !Dense<16, 16>::is_zero(15, 15));
}

TEST(Pattern, StructuredKernelsOnTwelveStatesEqualDenseBitForBit) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  Matrix<double, 12, 12> a;
  Matrix<double, 12, 12> p;
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = 0; j < 12; ++j) {
      a(i, j) = Chain12::is_one(i, j) ? 1.0 : Chain12::is_zero(i, j) ? 0.0 : g(rng);
      p(i, j) = g(rng);
    }
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = i; j < 12; ++j) p(j, i) = p(i, j);
  const auto structured = congruence<double, Chain12>(a, p);
  const auto dense = congruence<double, Dense<12, 12>>(a, p);
  const auto sp = product<double, Chain12, Dense<12, 12>>(a, p);
  const auto dp = product<double, Dense<12, 12>, Dense<12, 12>>(a, p);
  for (std::size_t k = 0; k < 144; ++k) {
    // Structural zeros add exact zeros and ones exact copies: the sums agree to rounding of the same terms.
    EXPECT_NEAR(structured[k], dense[k], 1e-12 * (1.0 + std::fabs(dense[k])));
    EXPECT_NEAR(sp[k], dp[k], 1e-12 * (1.0 + std::fabs(dp[k])));
  }
}

/// A 16-state structure with 4 inputs and 4 outputs compiles through the estimator.
struct Chain16 {
  static constexpr std::size_t kStates = 16;
  static constexpr std::size_t kInputs = 4;
  static constexpr std::size_t kOutputs = 4;
  // Φ₀₀ and Φ₁₅,₁₅ structurally one (words 0 and 3), Φ₁₅,₀ zero (word 3), the rest free.
  using PhiPattern = Pattern<16, 16, 0x0ULL, 0x1ULL, 0, 0, 0, 0, 0x1ULL << 48, 0x1ULL << 63>;
  using GammaPattern = Dense<16, 4>;
  using QdPattern = Dense<16, 16>;
  using ConstantQPattern = Dense<16, 16>;
  using OutputPattern = Dense<4, 16>;
  using FeedbackPattern = Dense<4, 16>;
  using StateFeedforwardPattern = Dense<16, 4>;
  using InputFeedforwardPattern = Dense<4, 4>;
};

TEST(Pattern, SixteenStateEstimatorCompilesAndRuns) {
  KalmanEstimator<UniformFormat<double>, Chain16> est;
  Matrix<double, 16, 16> p0 = Matrix<double, 16, 16>::identity();
  est.reset(Vector<double, 16>{}, p0);
  Discretization<UniformFormat<double>, 16, 4> d = Discretization<UniformFormat<double>, 16, 4>::identity();
  for (std::size_t i = 1; i < 16; ++i) d.phi(i, i) = 1.0;
  est.predict(d, Vector<double, 4>{}, NoiseModel::kExact, Matrix<double, 16, 16>{});
  Matrix<double, 4, 16> c;
  for (std::size_t o = 0; o < 4; ++o) c(o, o) = 1.0;
  Vector<double, 4> y;
  y[2] = 1.0;
  Vector<double, 4> r;
  for (std::size_t o = 0; o < 4; ++o) r[o] = 1.0;
  // Output 2 alone, P = I, R = 1: the gain is 1/2 and x̂₂ moves half way.
  EXPECT_EQ(est.correct(y, 0b0100, r, c), Status::kOk);
  EXPECT_EQ(est.state()[2], 0.5);
  EXPECT_EQ(est.covariance()(2, 2), 0.5);
  EXPECT_EQ(est.covariance()(3, 3), 1.0);
}

}  // namespace
}  // namespace oneshot
