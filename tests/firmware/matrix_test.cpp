/// @file matrix_test.cpp
/// @brief Matrix basics and the LU solver against Eigen.
#include <gtest/gtest.h>

#include <random>

#include "oneshot/linear_solve.hpp"
#include "oneshot/matrix.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot {
namespace {

TEST(Matrix, IdentityTransposeBlocks) {
  const auto eye = Matrix<double, 3, 3>::identity();
  EXPECT_EQ(eye(0, 0), 1.0);
  EXPECT_EQ(eye(0, 1), 0.0);
  const Matrix<double, 2, 3> a({1, 2, 3, 4, 5, 6});
  const Matrix<double, 3, 2> t = a.transposed();
  EXPECT_EQ(t(2, 1), 6.0);
  EXPECT_EQ(t(0, 1), 4.0);
  const auto b = a.block<0, 1, 2, 2>();
  EXPECT_EQ(b(1, 1), 6.0);
  Matrix<double, 4, 4> big;
  big.set_block<2, 1>(b);
  EXPECT_EQ(big(3, 2), 6.0);
  EXPECT_EQ(big(0, 0), 0.0);
}

TEST(Matrix, ProductMatchesEigen) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-2, 2);
  Matrix<double, 3, 4> a;
  Matrix<double, 4, 2> b;
  for (std::size_t k = 0; k < a.kSize; ++k) a[k] = u(rng);
  for (std::size_t k = 0; k < b.kSize; ++k) b[k] = u(rng);
  const Matrix<double, 3, 2> c = a * b;
  EXPECT_LT(test::relative_error(test::to_eigen(c), test::to_eigen(a) * test::to_eigen(b)), 1e-15);
}

TEST(LinearSolve, MatchesEigenAndDetectsSingular) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 100; ++trial) {
    Matrix<double, 4, 4> a;
    Matrix<double, 4, 2> b;
    for (std::size_t k = 0; k < a.kSize; ++k) a[k] = u(rng);
    for (std::size_t k = 0; k < b.kSize; ++k) b[k] = u(rng);
    Matrix<double, 4, 2> x;
    ASSERT_EQ(solve(a, b, x), Status::kOk);
    const test::MatX ref = test::to_eigen(a).fullPivLu().solve(test::to_eigen(b));
    EXPECT_LT(test::relative_error(test::to_eigen(x), ref), 1e-9);
  }
  const Matrix<double, 2, 2> singular({1, 2, 2, 4});
  Matrix<double, 2, 2> inv;
  EXPECT_EQ(invert(singular, inv), Status::kSingular);
}

}  // namespace
}  // namespace oneshot
