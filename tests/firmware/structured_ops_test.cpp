/// @file structured_ops_test.cpp
/// @brief Pattern-aware kernels equal their dense counterparts.
#include <gtest/gtest.h>

#include <random>

#include "oneshot/structured_ops.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot {
namespace {

// Φ-like pattern of the double integrator: [[1, *], [0, 1]].
using PhiP = Pattern<2, 2, 0x4, 0x9>;

template <typename S>
Matrix<S, 2, 2> structured(S free) {
  Matrix<S, 2, 2> m = Matrix<S, 2, 2>::identity();
  m(0, 1) = free;
  return m;
}

TEST(StructuredOps, PatternedEqualsDenseBitForBit) {
  // GIVEN matrices whose structural entries hold their exact 0/1 values
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int trial = 0; trial < 1000; ++trial) {
    const Matrix<float, 2, 2> phi = structured(u(rng));
    Matrix<float, 2, 2> p;
    p(0, 0) = u(rng) + 2;
    p(1, 1) = u(rng) + 2;
    p(0, 1) = p(1, 0) = u(rng);
    Matrix<float, 2, 2> q;
    q(0, 0) = u(rng);
    q(1, 1) = u(rng);
    q(0, 1) = q(1, 0) = u(rng);
    Vector<float, 2> x;
    x[0] = u(rng);
    x[1] = u(rng);
    Matrix<float, 2, 1> g;
    g[0] = u(rng);
    g[1] = u(rng);
    Vector<float, 1> in;
    in[0] = u(rng);
    // WHEN the structured and the dense kernels run
    const auto prod_s = product<float, PhiP, Dense<2, 2>>(phi, p);
    const auto prod_d = product<float, Dense<2, 2>, Dense<2, 2>>(phi, p);
    const auto aff_s = affine<float, PhiP, Dense<2, 1>>(phi, x, g, in);
    const auto aff_d = affine<float, Dense<2, 2>, Dense<2, 1>>(phi, x, g, in);
    const auto con_s = congruence_add<float, PhiP, Dense<2, 2>>(phi, p, q);
    const auto con_d = congruence_add<float, Dense<2, 2>, Dense<2, 2>>(phi, p, q);
    // THEN they agree exactly (adding ±0 and multiplying by 1 are exact)
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(prod_s[k], prod_d[k]);
      EXPECT_EQ(con_s[k], con_d[k]);
    }
    EXPECT_EQ(aff_s[0], aff_d[0]);
    EXPECT_EQ(aff_s[1], aff_d[1]);
    // AND the congruence is exactly symmetric and matches Eigen
    EXPECT_EQ(con_s(0, 1), con_s(1, 0));
    const test::MatX ref = test::to_eigen(phi) * test::to_eigen(p) * test::to_eigen(phi).transpose() + test::to_eigen(q);
    EXPECT_LT(test::relative_error(test::to_eigen(con_s), ref), 1e-6);
  }
}

TEST(StructuredOps, TransposedPatternMovesBits) {
  using P = Pattern<1, 2, 0x2, 0x1>;  // C = [1, 0]
  using T = Transposed<P>;
  static_assert(T::kRows == 2 && T::kCols == 1);
  static_assert(T::is_one(0, 0) && T::is_zero(1, 0));
}

}  // namespace
}  // namespace oneshot
