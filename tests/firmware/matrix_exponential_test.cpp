/// @file matrix_exponential_test.cpp
/// @brief Scaling and squaring against Eigen's matrix exponential.
#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>
#include <cmath>
#include <random>

#include "oneshot/matrix_exponential.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot {
namespace {

template <typename S, std::size_t N>
double max_relative_error_over_norms(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, 1);
  double worst = 0;
  for (double target : {1e-4, 1e-2, 0.3, 1.0, 3.0, 10.0, 30.0}) {
    for (int trial = 0; trial < 20; ++trial) {
      test::MatX m(static_cast<Eigen::Index>(N), static_cast<Eigen::Index>(N));
      for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = g(rng);
      m *= target / m.cwiseAbs().colwise().sum().maxCoeff();
      // Shift the spectrum left so e^M stays well scaled (a stable plant times t).
      m -= test::MatX::Identity(m.rows(), m.cols()) * 0.5 * target;
      Matrix<S, N, N> ours_in;
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = 0; j < N; ++j)
          ours_in(i, j) = static_cast<S>(m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)));
      Matrix<S, N, N> ours;
      EXPECT_EQ(matrix_exponential(ours_in, ours), Status::kOk);
      const test::MatX ref = test::to_eigen(ours_in).exp();
      worst = std::max(worst, test::relative_error(test::to_eigen(ours), ref));
    }
  }
  return worst;
}

TEST(MatrixExponential, DoubleMatchesEigen) {
  const double err = max_relative_error_over_norms<double, 4>(10);
  std::cout << "[ measured ] expm double 4x4 max relative error vs Eigen: " << err << "\n";
  EXPECT_LT(err, 1e-12);
}

TEST(MatrixExponential, FloatMatchesEigen) {
  const double err = max_relative_error_over_norms<float, 3>(11);
  std::cout << "[ measured ] expm float 3x3 max relative error vs Eigen: " << err << "\n";
  EXPECT_LT(err, 5e-5);
}

TEST(MatrixExponential, NilpotentIsExactPolynomial) {
  // e^{[[0, a], [0, 0]]} = [[1, a], [0, 1]] exactly, even with squarings.
  const Matrix<float, 2, 2> m({0.0F, -1.19F, 0.0F, 0.0F});
  Matrix<float, 2, 2> e;
  ASSERT_EQ(matrix_exponential(m, e), Status::kOk);
  EXPECT_EQ(e(0, 0), 1.0F);
  EXPECT_EQ(e(1, 0), 0.0F);
  EXPECT_EQ(e(1, 1), 1.0F);
  EXPECT_FLOAT_EQ(e(0, 1), -1.19F);
}

TEST(MatrixExponential, RejectsUnscalableNorm) {
  const Matrix<double, 1, 1> m({std::ldexp(1.0, 60)});
  Matrix<double, 1, 1> e;
  EXPECT_EQ(matrix_exponential(m, e), Status::kOutOfRange);
}

}  // namespace
}  // namespace oneshot
