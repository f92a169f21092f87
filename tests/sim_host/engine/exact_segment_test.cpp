/// @file exact_segment_test.cpp
/// @brief The interval maps of a zero-padded plant from the exponential of its coupled indices
///        (ExactSegmentCache::compact_segment()) against the dense exponential of the whole
///        padded generator (dense_segment()): the same bytes, interval length by length.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine {
namespace {

/// Every byte of two maps equal (Φ, Γ, G: padding and signed zeros included).
template <std::size_t N, std::size_t U>
bool same_bytes(const ExactSegment<N, U>& x, const ExactSegment<N, U>& y) {
  return std::memcmp(&x.phi, &y.phi, sizeof x.phi) == 0 && std::memcmp(&x.gamma, &y.gamma, sizeof x.gamma) == 0 &&
         std::memcmp(&x.g, &y.g, sizeof x.g) == 0;
}

/// Intervals of `count` whole-µs lengths in [1 µs, 20 ms] from `rng` (the loops' delays are whole µs).
template <std::size_t N, std::size_t U>
int differing(ExactSegmentCache<N, U>& cache, RandomStream& rng, int count) {
  int bad = 0;
  for (int t = 0; t < count; ++t) {
    const std::int64_t ns = static_cast<std::int64_t>(rng.uniform_int(1, 20000)) * 1000;
    const ExactSegment<N, U> dense = cache.dense_segment(ns);
    if (!same_bytes(dense, cache.compact_segment(ns))) ++bad;
    if (!same_bytes(dense, cache.get(ns))) ++bad;
  }
  return bad;
}

// The flexible structure of the study examples (n = 8, m = 1) in the shape (8, 4, 4): inputs
// 1..3 padded, no disturbance (B_w = 0): 9 coupled indices of 13. Measured: 0 of 1000 differ.
TEST(ExactSegmentCompact, PaddedInputsGiveTheDenseBytes) {
  const double w_hz[4] = {0.2, 0.5, 1, 1.6};
  const double b_k[4] = {1, 0.8, 0.6, 0.4};
  Matrix<double, 8, 8> a;
  Matrix<double, 8, 5> b;
  Matrix<double, 8, 8> q1c;
  for (std::size_t k = 0; k < 4; ++k) {  // d²q/dt² + 2ζω dq/dt + ω² q = b u, ζ = 0.05
    const double w = 2 * 3.141592653589793 * w_hz[k];
    a(2 * k, 2 * k + 1) = 1;
    a(2 * k + 1, 2 * k) = -w * w;
    a(2 * k + 1, 2 * k + 1) = -2 * 0.05 * w;
    b(2 * k + 1, 0) = b_k[k];
    q1c(2 * k, 2 * k) = 10;
    q1c(2 * k + 1, 2 * k + 1) = 0.1;
  }
  ExactSegmentCache<8, 5> cache(a, b, q1c);
  EXPECT_EQ(cache.coupled(), 9u);
  RandomStream rng(1, "exact segment flexible");
  EXPECT_EQ(differing(cache, rng, 1000), 0);
}

// Random plants with padded states and inputs (3 of 4 states, as the DC motor on (4, 1, 4);
// 10 of 16 states with 2 inputs) and a disturbance column. Measured: 0 differ.
TEST(ExactSegmentCompact, PaddedStatesGiveTheDenseBytes) {
  RandomStream rng(2, "exact segment random");
  for (int rep = 0; rep < 3; ++rep) {
    Matrix<double, 4, 2> b4;
    Matrix<double, 4, 4> a4;
    Matrix<double, 4, 4> q4;
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) a4(i, j) = 3 * rng.normal();
      q4(i, i) = 1 + rep;
      b4(i, 0) = rng.normal();
      b4(i, 1) = rng.normal();
    }
    ExactSegmentCache<4, 2> c4(a4, b4, q4);
    EXPECT_EQ(c4.coupled(), 5u);
    EXPECT_EQ(differing(c4, rng, 500), 0);
    Matrix<double, 16, 5> b16;
    Matrix<double, 16, 16> a16;
    Matrix<double, 16, 16> q16;
    for (std::size_t i = 0; i < 10; ++i) {
      for (std::size_t j = 0; j < 10; ++j) a16(i, j) = rng.normal();
      q16(i, i) = 1;
      b16(i, 0) = rng.normal();
      b16(i, 1) = rng.normal();
    }
    ExactSegmentCache<16, 5> c16(a16, b16, q16);
    EXPECT_EQ(c16.coupled(), 12u);
    EXPECT_EQ(differing(c16, rng, 100), 0);
  }
}

// A plant that fills its shape keeps the dense exponential (every index coupled).
TEST(ExactSegmentCompact, FullPlantIsDense) {
  const double a[4] = {0, 1, -4, -0.4};
  const double b[4] = {0, 0, 1, 0.5};
  ExactSegmentCache<2, 2> cache(Matrix<double, 2, 2>(a), Matrix<double, 2, 2>(b), Matrix<double, 2, 2>::identity());
  EXPECT_EQ(cache.coupled(), 4u);
  EXPECT_TRUE(same_bytes(cache.get(1234000), cache.dense_segment(1234000)));
}

// A state with no dynamics (zero row and column of A, no input) but a cost weight, and one with a
// cross weight only: both stay coupled (the cost integral G grows with them), so the compact map
// is the dense one. Measured: 0 differ.
TEST(ExactSegmentCompact, AStateWithCostButNoDynamicsStaysCoupled) {
  RandomStream rng(3, "exact segment cost only");
  Matrix<double, 4, 2> b;
  Matrix<double, 4, 4> a;
  Matrix<double, 4, 4> q;
  a(0, 1) = 1;
  a(1, 0) = -50;  // |A| ~ 50: several squarings at 20 ms
  a(1, 1) = -2;
  b(1, 0) = 1;
  q(0, 0) = 1;
  q(1, 1) = 0.1;
  q(2, 2) = 3;     // state 2: no dynamics, a weight
  q(0, 3) = 0.5;   // state 3: no dynamics, a cross weight only
  q(3, 0) = 0.5;
  ExactSegmentCache<4, 2> cache(a, b, q);
  EXPECT_EQ(cache.coupled(), 5u);  // states 0..3 and input 0; input 1 (and the absent disturbance) padded
  EXPECT_EQ(differing(cache, rng, 500), 0);
}

}  // namespace
}  // namespace oneshot::engine
